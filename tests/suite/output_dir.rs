//! The `--out` folder as a whole: it appears complete or not at all, replaces an earlier run's
//! folder without leaving stale files, refuses a folder flexcraft did not write (unless
//! `--force`), `/` and similar targets, survives concurrent runs and SIGTERM without leftovers;
//! and stdout write errors are errors, except a closed pipe.

use super::common::{assert_same_tree, bin, entries, example, scratch, tree};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

fn run(args: &[&std::ffi::OsStr]) -> std::process::Output {
    bin().args(args).output().unwrap()
}

#[test]
fn a_folder_not_written_by_flexcraft_is_refused_and_replaced_whole_with_force() {
    let dir = scratch("foreign");
    let out = dir.join("out");
    std::fs::create_dir_all(out.join("sub")).unwrap();
    std::fs::write(out.join("report.html"), "my own report").unwrap();
    std::fs::write(out.join("sub/notes.txt"), "my notes").unwrap();
    let before = tree(&out);
    let seed = example("seed.toml");
    let r = run(&[
        "simulate".as_ref(),
        seed.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&out.display().to_string()) && err.contains("--force"),
        "{err}"
    );
    assert!(err.contains("not written by flexcraft"), "{err}");
    assert!(r.stdout.is_empty(), "computed before refusing");
    assert_eq!(tree(&out), before, "the user's files were touched");
    assert_eq!(entries(&dir), vec!["out"], "leftovers beside the target");

    // With --force the folder is replaced as a whole: same tree as a fresh run.
    let r = run(&[
        "simulate".as_ref(),
        seed.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
        "--force".as_ref(),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    let fresh = dir.join("fresh");
    let r = run(&[
        "simulate".as_ref(),
        seed.as_os_str(),
        "--out".as_ref(),
        fresh.as_os_str(),
    ]);
    assert!(r.status.success());
    assert_same_tree(&out, &fresh);
    assert!(!out.join("sub").exists());
    assert_ne!(
        std::fs::read(out.join("report.html")).unwrap(),
        b"my own report"
    );
    assert!(out.join(".flexcraft-output").is_file());
    assert_eq!(entries(&dir), vec!["fresh", "out"]);
    // Ours now: a further run needs no --force. An empty folder needs none either.
    let r = run(&[
        "deploy".as_ref(),
        seed.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert!(
        !out.join("report.html").exists(),
        "merged with the earlier run"
    );
    let empty = dir.join("empty");
    std::fs::create_dir(&empty).unwrap();
    let r = run(&[
        "deploy".as_ref(),
        seed.as_os_str(),
        "--out".as_ref(),
        empty.as_os_str(),
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    assert_same_tree(&out, &empty);
    // A file is never replaced, even with --force.
    let file = dir.join("file");
    std::fs::write(&file, "x").unwrap();
    let r = run(&[
        "modes".as_ref(),
        seed.as_os_str(),
        "--out".as_ref(),
        file.as_os_str(),
        "--force".as_ref(),
    ]);
    assert_eq!(r.status.code(), Some(2));
    assert_eq!(std::fs::read(&file).unwrap(), b"x");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_second_scenario_into_the_same_folder_leaves_no_stale_files() {
    let dir = scratch("stale");
    let out = dir.join("out");
    let fresh = dir.join("fresh");
    let (full, tip) = (example("full.toml"), example("tip_mass.toml"));
    let mut counts = Vec::new();
    for (s, o) in [(&full, &out), (&tip, &out), (&tip, &fresh)] {
        let r = run(&[
            "modes".as_ref(),
            s.as_os_str(),
            "--out".as_ref(),
            o.as_os_str(),
        ]);
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        counts.push(tree(o).len());
    }
    assert!(
        counts[0] > counts[1],
        "the second scenario has fewer files: {counts:?}"
    );
    assert_same_tree(&out, &fresh);
    assert_eq!(entries(&dir), vec!["fresh", "out"]);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_symlinked_out_is_written_at_its_real_location() {
    #[cfg(unix)]
    {
        let dir = scratch("symlink");
        let real = dir.join("real");
        let link = dir.join("link");
        std::fs::create_dir(&real).unwrap();
        std::os::unix::fs::symlink(&real, &link).unwrap();
        let seed = example("seed.toml");
        for _ in 0..2 {
            let r = run(&[
                "deploy".as_ref(),
                seed.as_os_str(),
                "--out".as_ref(),
                link.as_os_str(),
            ]);
            assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        }
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert!(real.join("events.json").is_file());
        assert_eq!(entries(&dir), vec!["link", "real"]);
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn sigterm_leaves_neither_the_folder_nor_staging_nor_lock() {
    #[cfg(unix)]
    {
        let dir = scratch("sigterm");
        let (mut child, _) = super::common::simulate_until_staging(&dir, &dir.join("new"));
        std::thread::sleep(Duration::from_millis(100));
        let killed = Command::new("kill")
            .args(["-TERM", &child.id().to_string()])
            .status()
            .unwrap();
        assert!(killed.success());
        let status = child.wait().unwrap();
        assert!(!status.success(), "the run finished before SIGTERM");
        assert_eq!(status.code(), Some(130));
        // The folder `new` was created for the run: it goes too.
        assert_eq!(entries(&dir), vec!["long.toml"]);
        let _ = std::fs::remove_dir_all(&dir);
    }
}

#[test]
fn concurrent_runs_into_one_new_folder_are_serialised() {
    let dir = scratch("concurrent");
    let out = dir.join("out");
    let seed = example("seed.toml");
    for _ in 0..3 {
        let _ = std::fs::remove_dir_all(&out);
        let children: Vec<_> = (0..2)
            .map(|_| {
                bin()
                    .arg("modes")
                    .arg(&seed)
                    .arg("--out")
                    .arg(&out)
                    .stdout(Stdio::null())
                    .stderr(Stdio::piped())
                    .spawn()
                    .unwrap()
            })
            .collect();
        for c in children {
            let r = c.wait_with_output().unwrap();
            assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        }
        assert_eq!(entries(&dir), vec!["out"], "staging or lock left behind");
    }
    let single = dir.join("single");
    let r = run(&[
        "modes".as_ref(),
        seed.as_os_str(),
        "--out".as_ref(),
        single.as_os_str(),
    ]);
    assert!(r.status.success());
    assert_same_tree(&out, &single);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn root_is_refused_without_writing_anything() {
    let seed = example("seed.toml");
    for args in [
        vec!["modes", "--out", "/"],
        vec!["modes", "--out", "/", "--force"],
        vec!["simulate", "--out", "/", "--force"],
    ] {
        let r = bin()
            .arg(args[0])
            .arg(&seed)
            .args(&args[1..])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&r.stderr);
        assert_eq!(r.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains("error: /:"), "{err}");
        assert!(r.stdout.is_empty());
    }
    for f in [".flexcraft-output", "modes.json", "summary.json", "plots"] {
        assert!(!Path::new("/").join(f).exists(), "/{f} written");
    }
    // The home folder likewise, when there is one.
    if let Some(home) = std::env::var_os("HOME").filter(|h| Path::new(h).is_dir()) {
        let r = bin()
            .arg("modes")
            .arg(&seed)
            .arg("--out")
            .arg(&home)
            .arg("--force")
            .output()
            .unwrap();
        assert_eq!(r.status.code(), Some(2));
        assert!(String::from_utf8_lossy(&r.stderr).contains("home"));
    }
}

#[test]
fn stdout_write_errors_fail_but_a_closed_pipe_does_not() {
    let seed = example("seed.toml");
    if Path::new("/dev/full").exists() {
        let dir = scratch("devfull");
        let out = dir.join("made/for/out");
        for args in [vec!["simulate", "--json"], vec!["modes"]] {
            let full = std::fs::OpenOptions::new()
                .write(true)
                .open("/dev/full")
                .unwrap();
            let r = bin()
                .arg(args[0])
                .arg(&seed)
                .args(&args[1..])
                .arg("--out")
                .arg(&out)
                .stdout(full)
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&r.stderr);
            assert_eq!(r.status.code(), Some(1), "{args:?}: {err}");
            assert!(err.contains("error: writing to stdout"), "{err}");
            // A failed run leaves nothing, not even the parents made for --out.
            assert!(entries(&dir).is_empty(), "{:?}", entries(&dir));
        }
        let _ = std::fs::remove_dir_all(&dir);
    }
    // `flexcraft modes … | head -1` with the reader gone before the write: success.
    let dir = scratch("pipe");
    let out = dir.join("out");
    let mut child = bin()
        .arg("modes")
        .arg(&seed)
        .arg("--out")
        .arg(&out)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let r = child.wait_with_output().unwrap();
    assert_eq!(
        r.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    assert!(
        r.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&r.stderr)
    );
    assert!(out.join("modes.json").is_file());
    let _ = std::fs::remove_dir_all(&dir);
}
