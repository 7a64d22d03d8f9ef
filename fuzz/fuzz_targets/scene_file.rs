//! A scene file (JSON) beside an OBJ model and a glTF model it may name (`m.obj`, `m.gltf`,
//! both valid), loaded as `manylight --scene s.json` loads it. A scene file is the user's own,
//! like a command line, so it may name files anywhere; what it names is still read bounded.
#![no_main]

use libfuzzer_sys::fuzz_target;
use manylight_fuzz::{load_and_check, Folder};

fuzz_target!(|data: &[u8]| {
    load_and_check(&Folder::get().write("s.json", data), false);
});
