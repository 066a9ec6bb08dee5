//! `lens trace` input on arbitrary bytes: JSON → cases → traced rays, with
//! no panic or hang, refusals of one line, and the streamed output equal to
//! the whole output (tests/fuzz_corpus.rs replays the corpus the same way
//! with `cargo test`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    lensview::lens_tools::check_trace_bytes(data);
});
