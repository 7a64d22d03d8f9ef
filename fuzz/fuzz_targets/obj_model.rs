//! An OBJ file, its MTL file and one texture, loaded as `manylight --scene m.obj` loads them.
//! The input is the three files' bytes, separated by a byte 0xFF (`m.obj`, `m.mtl`, `t.png`:
//! the seeds name them; the texture's bytes may be in any format the library reads).
#![no_main]

use libfuzzer_sys::fuzz_target;
use manylight_fuzz::{load_and_check, split, Folder};

fuzz_target!(|data: &[u8]| {
    let folder = Folder::get();
    folder.write_parts(&["m.obj", "m.mtl", "t.png"], &split(data, 3));
    load_and_check(&folder.path("m.obj"), true);
});
