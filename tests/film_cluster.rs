//! Issue #35, item 3: a film rendered on a local Ray cluster (a head and two
//! worker nodes, in their own network namespace so they listen on the
//! loopback only) by tools/ray_film.py, with a worker node killed mid-run,
//! has every frame exactly once and byte-identical to the film made on one
//! machine. The script (tools/ray_film_test.sh) starts the cluster and stops
//! it, and every process it started ends with it (its own PID namespace).
//! Needs root (unshare), iproute2 and Ray from PyPI (`.ci/run` installs it).

use std::path::PathBuf;
use std::process::Command;

#[test]
fn a_film_on_a_ray_cluster_survives_a_lost_worker_node() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let work = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("film-cluster");
    let _ = std::fs::remove_dir_all(&work);
    std::fs::create_dir_all(&work).unwrap();
    let flight = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("film-cluster-flight.toml");
    std::fs::write(
        &flight,
        "version = 1\n\n[[poses]]\nt = 0\nposition = [0, 1.2, 6]\nrotation = [-5, 0, 0]\n\n\
         [[poses]]\nt = 1.0\nposition = [1.5, 1.2, 4]\nrotation = [-5, 20, 0]\n\n\
         [[poses]]\nt = 2.0\nposition = [2.5, 1.5, 2]\nrotation = [-10, 40, 0]\n",
    )
    .unwrap();
    let o = Command::new("bash")
        .arg(root.join("tools/ray_film_test.sh"))
        .arg(env!("CARGO_BIN_EXE_lensview"))
        .arg(root.join("scenes/cubes.toml"))
        .arg(&flight)
        .arg(work.join("run"))
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&o.stdout);
    let err = String::from_utf8_lossy(&o.stderr);
    eprintln!("{out}");
    assert!(o.status.success(), "the cluster test failed:\n{out}\n{err}");
    assert!(out.contains("killed the raylet"), "{out}");
    assert!(out.contains("OK: 13 frames, each once"), "{out}");
}
