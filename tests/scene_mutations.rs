//! The streaming scene reader against the whole-document parser on
//! byte-level mutations of real scene files, made where the two readers
//! could part: around table headers (`[[objects]]`, `[[lenses]]`), line
//! breaks (LF, CRLF, a lone CR), comments and byte-order marks. Every mutant goes through
//! the fuzz oracle (`check_scene_bytes`: what the streaming reader accepts
//! is what the whole document gives; a refusal is the whole document's
//! line, column and message, one line), and none may panic. Seeded, so a
//! failure names a case that replays.

use lensview::scene::check_scene_bytes;

/// Bytes that matter to the two readers' scanning.
const BYTES: &[&[u8]] = &[
    b"\r",
    b"\n",
    b"\r\n",
    b"[",
    b"]",
    b"[[",
    b"]]",
    b"#",
    b"\"",
    b"'",
    b"=",
    b" ",
    b"\t",
    b",",
    b"{",
    b"}",
    b"[[objects]]",
    b"[[lenses]]",
    b"objects = [",
    b"\"\"\"",
    b"\xff",
    b"\x00",
    b"x",
    // A byte-order mark (allowed only at the very start of a document).
    b"\xef\xbb\xbf",
];

/// A small counter-based generator (splitmix64).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Offsets next to the features the readers scan: header brackets, line
/// breaks, comment marks.
fn hot_spots(text: &[u8]) -> Vec<usize> {
    let mut v: Vec<usize> = (0..text.len())
        .filter(|&i| matches!(text[i], b'[' | b']' | b'\n' | b'\r' | b'#'))
        .flat_map(|i| [i, i + 1])
        .filter(|&i| i <= text.len())
        .collect();
    v.push(0);
    v.push(text.len());
    v
}

/// One to three edits (insert, delete, replace a few bytes) at hot spots.
fn mutate(text: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut t = text.to_vec();
    for _ in 0..1 + rng.below(3) {
        let spots = hot_spots(&t);
        let at = spots[rng.below(spots.len())];
        let piece = BYTES[rng.below(BYTES.len())];
        match rng.below(3) {
            0 => {
                t.splice(at..at, piece.iter().copied());
            }
            1 => {
                let end = (at + 1 + rng.below(3)).min(t.len());
                t.drain(at.min(end)..end);
            }
            _ => {
                let end = (at + piece.len()).min(t.len());
                t.splice(at.min(end)..end, piece.iter().copied());
            }
        }
    }
    t
}

fn seeds() -> Vec<Vec<u8>> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes");
    let mut v: Vec<Vec<u8>> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| std::fs::read(p).unwrap())
        .filter(|b| b.len() < 20_000)
        .collect();
    v.sort();
    // Both object forms, headers back to back, CRLF text, comments.
    v.push(b"[[objects]]\ntype = \"sphere\"\nradius = 1\n[[lenses]]\nd = 2\nr1 = 5\nr2 = 5\nn = 1.5\n".to_vec());
    v.push(b"[[objects]]\r\ntype = \"cuboid\" # c\r\nsize = [1, 1, 1]\r\n# x\r\n[[objects]]\r\ntype = \"sphere\"\r\nradius = 2\r\n".to_vec());
    v.push(b"objects = [ # a\n {type = \"sphere\", radius = 1}, # b\n]\n[camera]\nposition = [0, 1, 5]\n".to_vec());
    v
}

#[test]
fn the_streaming_reader_agrees_with_the_whole_document_on_mutants() {
    // The case the adversarial run found: a lone CR between two headers.
    for text in [
        &b"[[objects]]\r[[lenses]]"[..],
        b"[[objects]]\rtype=1\n[[objects]]",
        b"a=1\r\n[[objects]]\r",
    ] {
        let r = std::panic::catch_unwind(|| check_scene_bytes(text));
        assert!(r.is_ok(), "{:?} fails the oracle", String::from_utf8_lossy(text));
    }
    let seeds = seeds();
    assert!(seeds.len() >= 6, "{} seeds", seeds.len());
    let mut rng = Rng(std::env::var("LENSVIEW_MUTANT_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(0x5eed));
    let mut failed = Vec::new();
    // LENSVIEW_MUTANTS=N runs more (the test's own 4000 take 2 s).
    let cases: usize = std::env::var("LENSVIEW_MUTANTS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(4000);
    for case in 0..cases {
        let seed = &seeds[case % seeds.len()];
        let text = mutate(seed, &mut rng);
        if std::panic::catch_unwind(|| check_scene_bytes(&text)).is_err() {
            failed.push((case, String::from_utf8_lossy(&text).into_owned()));
        }
    }
    assert!(
        failed.is_empty(),
        "{} of {cases} mutants fail the oracle; first: {:?}",
        failed.len(),
        failed.first()
    );
}

/// Arrays and inline tables nested 10⁰…10⁶ deep, inside an object and at
/// the top: a one-line refusal with its line and column, on a test thread's
/// small stack (2 MiB). Before, the out-of-range number pass recursed once
/// a level and 10 000 levels overflowed even the main thread's 8 MiB
/// (SIGABRT, found by replaying the fuzzer's corpus on a test thread).
#[test]
fn deep_nesting_is_refused_without_overflowing_the_stack() {
    for n in [1usize, 10, 100, 1_000, 10_000, 1_000_000] {
        for (open, close) in [("[", "]"), ("{a = ", "}")] {
            let deep = format!("{}1{}", open.repeat(n), close.repeat(n));
            for text in [
                format!(
                    "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\n[[objects]]\ntype = \"sphere\"\nradius = 1\nx = {deep}\n"
                ),
                format!("x = {deep}\n[camera]\nposition = [0, 0, 5]\n"),
            ] {
                let got = std::thread::spawn(move || {
                    lensview::scene::Scene::parse("deep.toml", &text)
                        .map(|_| ())
                        .map_err(|e| e.to_string())
                })
                .join()
                .expect("no overflow, no panic");
                let e = got.expect_err("refused");
                assert!(e.starts_with("deep.toml:"), "{n} {open}: {e}");
                assert_eq!(e.lines().count(), 1, "{e}");
            }
        }
    }
}
