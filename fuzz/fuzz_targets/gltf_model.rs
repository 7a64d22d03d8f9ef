//! A glTF model with a buffer and an image beside it, loaded as `manylight --scene` loads it.
//! The input's first byte picks the form (even: `m.gltf`, JSON; odd: `m.glb`, binary), the
//! rest is the model's, the buffer's and the image's bytes, separated by a byte 0xFF
//! (`b.bin`, `t.png`: the seeds name them).
#![no_main]

use libfuzzer_sys::fuzz_target;
use manylight_fuzz::{load_and_check, split, Folder};

fuzz_target!(|data: &[u8]| {
    let Some((&form, rest)) = data.split_first() else {
        return;
    };
    let folder = Folder::get();
    let model = if form % 2 == 0 { "m.gltf" } else { "m.glb" };
    // A GLB is binary throughout: its buffer and image, if any, are inside it.
    let parts = if form % 2 == 0 {
        split(rest, 3)
    } else {
        vec![rest]
    };
    folder.write_parts(&[model, "b.bin", "t.png"], &parts);
    load_and_check(&folder.path(model), true);
});
