//! The scene parser and validator on arbitrary bytes: no panic, no hang, and
//! a refusal is one line (tests/fuzz_corpus.rs replays the corpus the same
//! way with `cargo test`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    lensview::scene::check_scene_bytes(data);
});
