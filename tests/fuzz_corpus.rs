//! Replays the fuzz corpora (fuzz/corpus/scene, fuzz/corpus/lens_trace) and
//! any crash inputs kept (fuzz/artifacts/TARGET) through the fuzz target's own oracle, so that plain
//! `cargo test` checks every input the fuzzer has found interesting.

use std::path::{Path, PathBuf};

fn files_under(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries {
        let p = e.unwrap().path();
        if p.is_dir() {
            files_under(&p, out);
        } else {
            out.push(p);
        }
    }
}

/// Every input of fuzz target `target` (its corpus, at least `seeds`
/// files, then its crash inputs), each read and passed through `oracle`,
/// which must not panic; returns the inputs' bytes.
fn replay(target: &str, seeds: usize, oracle: fn(&[u8])) -> Vec<Vec<u8>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    let mut all = Vec::new();
    files_under(&root.join("corpus").join(target), &mut all);
    assert!(all.len() >= seeds, "{target}: seed corpus missing: {} files", all.len());
    files_under(&root.join("artifacts").join(target), &mut all);
    all.sort();
    let mut inputs = Vec::new();
    for f in &all {
        let bytes = std::fs::read(f).unwrap();
        let outcome = std::panic::catch_unwind(|| oracle(&bytes));
        assert!(outcome.is_ok(), "{} fails the fuzz oracle", f.display());
        inputs.push(bytes);
    }
    inputs
}

#[test]
fn fuzz_corpus_and_artifacts_replay_without_panic() {
    let all = replay("scene", 10, lensview::scene::check_scene_bytes);
    let loaded = all
        .iter()
        .filter(|b| lensview::scene::Scene::from_bytes("x.toml", b).is_ok())
        .count();
    // The shipped scenes are in the seed corpus: some inputs load.
    assert!(loaded >= 3, "only {loaded} of {} inputs load", all.len());
}

/// The `lens trace` corpus (fuzz/corpus/lens_trace) and its crash inputs
/// (fuzz/artifacts/lens_trace) through `check_trace_bytes`, the oracle of
/// fuzz/fuzz_targets/lens_trace.rs.
#[test]
fn lens_trace_corpus_and_artifacts_replay_without_panic() {
    use lensview::lens_tools::{TraceInput, check_cases};
    let all = replay("lens_trace", 8, lensview::lens_tools::check_trace_bytes);
    let (mut traced, mut refused) = (0, 0);
    for input in all.iter().filter_map(|b| serde_json::from_slice::<TraceInput>(b).ok()) {
        match check_cases(&input) {
            Ok(()) => traced += 1,
            Err(_) => refused += 1,
        }
    }
    // The seeds hold inputs of both kinds: the oracle's two halves both run.
    assert!(
        traced >= 3 && refused >= 3,
        "{traced} traced, {refused} refused of {}",
        all.len()
    );
}
