//! Hardening of the outputs (issue items 7, 8, 1, 3): byte-identical results whatever the
//! thread count, names escaped for every destination (CSV, HTML, JSON in `<script>`, file
//! names), and long series decimated for plotting.

use super::common::{bin, example, scratch};
use std::path::{Path, PathBuf};

/// Every file below `root`, as paths relative to it, sorted.
fn tree(root: &Path) -> Vec<PathBuf> {
    fn walk(root: &Path, rel: &Path, out: &mut Vec<PathBuf>) {
        for e in std::fs::read_dir(root.join(rel)).unwrap() {
            let e = e.unwrap();
            let r = rel.join(e.file_name());
            if e.file_type().unwrap().is_dir() {
                walk(root, &r, out);
            } else {
                out.push(r);
            }
        }
    }
    let mut files = Vec::new();
    walk(root, Path::new(""), &mut files);
    files.sort();
    files
}

/// The two trees hold the same files with the same bytes; returns the number of files.
fn assert_identical_trees(a: &Path, b: &Path) -> usize {
    let (fa, fb) = (tree(a), tree(b));
    assert_eq!(
        fa,
        fb,
        "{} and {} list different files",
        a.display(),
        b.display()
    );
    for f in &fa {
        let x = std::fs::read(a.join(f)).unwrap();
        let y = std::fs::read(b.join(f)).unwrap();
        assert!(
            x == y,
            "{} differs between {} and {}",
            f.display(),
            a.display(),
            b.display()
        );
    }
    fa.len()
}

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
            let n = assert_identical_trees(&runs[0], &runs[1]);
            assert!(n > 5, "{ex} {sub}: only {n} files");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
