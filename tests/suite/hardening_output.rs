//! Hardening of the outputs (issue items 7, 8, 1, 3): byte-identical results whatever the
//! thread count, names escaped for every destination (CSV, HTML, JSON in `<script>`, file
//! names), and long series decimated for plotting.

use super::common::{assert_same_tree, bin, example, scratch};
use std::path::PathBuf;

/// Item 7: `modes --out` and `simulate --out` give the same bytes with 1 and 2 threads.
#[test]
fn outputs_are_byte_identical_with_one_and_two_threads() {
    let dir = scratch("threads");
    for ex in ["seed.toml", "free_hub.toml"] {
        for sub in ["modes", "simulate"] {
            let runs: Vec<PathBuf> = ["1", "2"]
                .iter()
                .map(|threads| {
                    let out = dir.join(format!("{ex}-{sub}-{threads}"));
                    let r = bin()
                        .env("RAYON_NUM_THREADS", threads)
                        .arg(sub)
                        .arg(example(ex))
                        .arg("--out")
                        .arg(&out)
                        .output()
                        .unwrap();
                    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
                    out
                })
                .collect();
            let n = assert_same_tree(&runs[0], &runs[1]);
            assert!(n > 5, "{ex} {sub}: only {n} files");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
