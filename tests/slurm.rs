//! examples/slurm on a real one-node Slurm cluster (scripts/slurm_local.sh): an array job of
//! 4 shards and a merge job that depends on it, whose merged state, PNG and report must equal, byte for
//! byte, the same shards rendered here and merged in reverse order. Skipped, saying why, only
//! where the cluster cannot be started (not root, or slurm-wlm and munge not installable).

use std::process::Command;

#[test]
fn slurm_array_job_and_dependent_merge_equal_the_local_merge() {
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/scripts/slurm_local.sh");
    let out = Command::new("bash")
        .args([script, env!("CARGO_BIN_EXE_candela"), "4", "16"])
        .output()
        .unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    println!("{stdout}");
    if out.status.code() == Some(77) {
        println!("SKIPPED: {}", stderr.trim());
        return;
    }
    assert!(out.status.success(), "{stdout}\n{stderr}");
    assert!(
        stdout.contains("render.png from Slurm equals the local merge"),
        "{stdout}"
    );
    assert!(
        stdout.contains("render.report.json from Slurm equals the local merge"),
        "{stdout}"
    );
    assert!(
        stdout.contains("render.state from Slurm equals the local merge"),
        "{stdout}"
    );
    assert!(
        stdout.contains("merged shards [0, 1, 2, 3] of 4"),
        "{stdout}"
    );
}
