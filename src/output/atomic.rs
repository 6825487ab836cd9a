//! An output directory that appears whole or not at all.
//!
//! [`OutputDir::create`] does every check that can fail before the caller computes anything:
//! it refuses `/`, the user's home, the current directory or one of its ancestors, a mount
//! point, an existing non-directory, and an existing non-empty directory that flexcraft did not
//! write (no [`MARKER`] file) unless `force`. It then takes an exclusive lock (a file
//! `.NAME.lock` beside the target, so concurrent runs into one folder are serialised) and
//! creates a hidden staging directory `.NAME.partial-HOST-PID` beside the *real* location of the
//! target (a symbolic link is resolved), on the same file system. Files are written into the
//! staging directory; [`OutputDir::commit`] adds the marker and swaps the complete folder in
//! with renames: the old folder, if any, is replaced as a whole, never merged. If anything fails,
//! the value is dropped uncommitted, or the process gets SIGINT/SIGTERM, the staging directory,
//! the lock file and any parent folder created for the target are removed and the old folder is
//! left as it was. A process killed without a chance to clean (SIGKILL, SIGQUIT) leaves its
//! staging folder (and, killed between the swap's two renames, the previous output as
//! `.NAME.old-HOST-PID`): the next run into the same target removes those of dead processes of
//! its own host, and puts such a backup back first where the target is missing.

use super::OutputError;
use std::collections::{BTreeMap, BTreeSet};
use std::fs::File;
use std::io::ErrorKind;
use std::path::{Component, Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, MutexGuard, Once};

/// The marker file every output folder of flexcraft carries; its content is the same for every
/// run, so outputs stay byte-identical.
pub const MARKER: &str = ".flexcraft-output";
const MARKER_TEXT: &str =
    "Written by flexcraft. The next run with --out here replaces this folder as a whole.\n";

/// What the signal handler (or a failed run) must remove for one output directory.
#[derive(Debug, Default)]
struct Cleanup {
    /// Directories removed with everything in them (staging, backup of the old folder).
    trees: Vec<PathBuf>,
    /// The lock file, removed while the lock is still held.
    lock_file: Option<PathBuf>,
    /// Parent folders created for the target, outermost first; removed only if empty.
    parents: Vec<PathBuf>,
}

impl Cleanup {
    fn run(&self) {
        for t in &self.trees {
            remove_tree(t);
        }
        if let Some(l) = &self.lock_file {
            let _ = std::fs::remove_file(l);
        }
        for p in self.parents.iter().rev() {
            let _ = std::fs::remove_dir(p);
        }
    }
}

/// Removes a directory tree; retried because a file may be in flight in another thread when
/// the signal handler runs.
fn remove_tree(p: &Path) {
    for _ in 0..20 {
        match std::fs::remove_dir_all(p) {
            Err(e) if e.kind() != ErrorKind::NotFound => {
                std::thread::sleep(std::time::Duration::from_millis(5));
            }
            _ => return,
        }
    }
}

/// The live output directories of this process, by id; the signal handler cleans them all.
static REGISTRY: Mutex<BTreeMap<u64, Cleanup>> = Mutex::new(BTreeMap::new());
static NEXT_ID: AtomicU64 = AtomicU64::new(0);
static HANDLER: Once = Once::new();

fn registry() -> MutexGuard<'static, BTreeMap<u64, Cleanup>> {
    REGISTRY
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// On SIGINT/SIGTERM (Ctrl-C on Windows): remove every staging directory, lock file and
/// created parent, then exit with status 130. The registry stays locked until the exit, so no
/// new staging file or folder can be made meanwhile.
fn install_handler() {
    HANDLER.call_once(|| {
        let _ = ctrlc::set_handler(|| {
            let reg = registry();
            for c in reg.values() {
                c.run();
            }
            std::process::exit(130);
        });
    });
}

/// A staged output directory.
#[derive(Debug)]
pub struct OutputDir {
    id: u64,
    /// The target as the user named it (for messages).
    shown: PathBuf,
    /// The target at its real location: canonical parent joined with the name.
    target: PathBuf,
    staging: PathBuf,
    backup: PathBuf,
    lock: Option<File>,
    files: BTreeSet<PathBuf>,
    committed: bool,
}

fn forbidden(dir: &Path, reason: &str) -> OutputError {
    OutputError::ForbiddenTarget {
        dir: dir.to_path_buf(),
        reason: reason.to_string(),
    }
}

/// Refuses an output folder that is, or holds, one of the command's inputs (the scenario, a
/// shard folder being merged): replacing it would delete what the run reads, `--force` or
/// not. Paths that do not exist yet cannot hold anything.
pub fn refuse_inputs_inside(target: &Path, inputs: &[&Path]) -> Result<(), OutputError> {
    let Ok(real) = std::fs::canonicalize(target) else {
        return Ok(());
    };
    for input in inputs {
        if let Ok(i) = std::fs::canonicalize(input) {
            if i.starts_with(&real) {
                return Err(forbidden(
                    target,
                    &format!(
                        "holds the input {} (it would be replaced; choose another folder)",
                        input.display()
                    ),
                ));
            }
        }
    }
    Ok(())
}

fn io_at(path: &Path, what: &str, e: std::io::Error) -> OutputError {
    OutputError::Io(std::io::Error::new(
        e.kind(),
        format!("{what} {}: {e}", path.display()),
    ))
}

/// The user's home folder, canonical, if known.
fn home() -> Option<PathBuf> {
    let var = if cfg!(windows) { "USERPROFILE" } else { "HOME" };
    let h = std::env::var_os(var)?;
    if h.is_empty() {
        return None;
    }
    std::fs::canonicalize(h).ok()
}

/// Refuses an existing target that is not a directory, or a non-empty one without our
/// marker (unless `force`).
fn check_existing(shown: &Path, real: &Path, force: bool) -> Result<(), OutputError> {
    let meta = match std::fs::symlink_metadata(real) {
        Ok(m) => m,
        Err(e) if e.kind() == ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(io_at(shown, "reading", e)),
    };
    if !meta.is_dir() {
        return Err(forbidden(shown, "exists and is not a directory"));
    }
    if force || real.join(MARKER).is_file() {
        return Ok(());
    }
    let mut entries = std::fs::read_dir(real).map_err(|e| io_at(shown, "reading", e))?;
    if entries.next().is_some() {
        return Err(OutputError::NotOurs {
            dir: shown.to_path_buf(),
        });
    }
    Ok(())
}

/// Checks a relative file name: only plain components, no NUL, not empty.
fn safe_relative(rel: &str) -> Result<PathBuf, OutputError> {
    let unsafe_path = |reason: &'static str| OutputError::UnsafePath {
        name: rel.escape_debug().to_string(),
        reason,
    };
    if rel.contains('\0') {
        return Err(unsafe_path("contains NUL"));
    }
    let p = Path::new(rel);
    if p.is_absolute() || p.has_root() {
        return Err(unsafe_path("is absolute"));
    }
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            Component::Normal(n) => out.push(n),
            Component::ParentDir => return Err(unsafe_path("contains ..")),
            Component::CurDir => return Err(unsafe_path("contains .")),
            Component::RootDir | Component::Prefix(_) => {
                return Err(unsafe_path("has a root or prefix"))
            }
        }
    }
    if out.as_os_str().is_empty() {
        return Err(unsafe_path("is empty"));
    }
    Ok(out)
}

impl OutputDir {
    /// Checks `target` (which need not exist), locks it and prepares a staging directory
    /// beside it. Call before the computation: every refusal happens here.
    ///
    /// # Errors
    /// [`OutputError::ForbiddenTarget`] or [`OutputError::NotOurs`] for a target that must not
    /// be replaced; [`OutputError::Io`] if a folder, the lock or the staging directory could not
    /// be made.
    pub fn create(target: &Path, force: bool) -> Result<Self, OutputError> {
        install_handler();
        let shown = target.to_path_buf();
        let id = NEXT_ID.fetch_add(1, Ordering::Relaxed);
        // Resolve the real location without creating anything yet.
        let (parent, name) = match std::fs::symlink_metadata(target) {
            Ok(_) => {
                let real = std::fs::canonicalize(target).map_err(|e| match e.kind() {
                    ErrorKind::NotFound => forbidden(target, "is a broken symbolic link"),
                    _ => io_at(target, "resolving", e),
                })?;
                match (real.parent(), real.file_name()) {
                    (Some(p), Some(n)) => (p.to_path_buf(), n.to_os_string()),
                    _ => return Err(forbidden(target, "is the root folder")),
                }
            }
            Err(e) if e.kind() == ErrorKind::NotFound => {
                let name = match target.components().next_back() {
                    Some(Component::Normal(n)) => n.to_os_string(),
                    _ => return Err(forbidden(target, "names no folder")),
                };
                let parent = match target.parent() {
                    Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
                    _ => PathBuf::from("."),
                };
                (parent, name)
            }
            Err(e) => return Err(io_at(target, "reading", e)),
        };
        let mut me = Self {
            id,
            shown: shown.clone(),
            target: PathBuf::new(),
            staging: PathBuf::new(),
            backup: PathBuf::new(),
            lock: None,
            files: BTreeSet::new(),
            committed: false,
        };
        registry().insert(id, Cleanup::default());
        // Parents that do not exist yet: created now, removed again if the run fails.
        let mut missing = Vec::new();
        for a in parent.ancestors() {
            if a.as_os_str().is_empty() || a.exists() {
                break;
            }
            missing.push(a.to_path_buf());
        }
        for p in missing.iter().rev() {
            match std::fs::create_dir(p) {
                Ok(()) => {
                    let abs = std::fs::canonicalize(p).map_err(|e| io_at(p, "resolving", e))?;
                    registry().entry(id).or_default().parents.push(abs);
                }
                Err(e) if e.kind() == ErrorKind::AlreadyExists => {}
                Err(e) => return Err(io_at(p, "creating", e)),
            }
        }
        let parent = std::fs::canonicalize(&parent).map_err(|e| io_at(&parent, "resolving", e))?;
        let real = parent.join(&name);
        me.target = real.clone();
        if let Some(h) = home() {
            if real == h {
                return Err(forbidden(&shown, "is your home folder"));
            }
        }
        if let Ok(cwd) = std::env::current_dir().and_then(std::fs::canonicalize) {
            if cwd.starts_with(&real) {
                return Err(forbidden(&shown, "is the current folder or contains it"));
            }
        }
        if let (Ok(t), Ok(p)) = (std::fs::metadata(&real), std::fs::metadata(&parent)) {
            if t.is_dir() && !same_device(&t, &p) {
                return Err(forbidden(
                    &shown,
                    "is a mount point (it cannot be replaced as a whole)",
                ));
            }
        }
        check_existing(&shown, &real, force)?;
        // The lock, then the checks again: another run may have changed the target meanwhile.
        let name = name.to_string_lossy().into_owned();
        let lock_path = parent.join(format!(".{name}.lock"));
        me.lock = Some(lock(&lock_path, id)?);
        let pid = std::process::id();
        let host = host_name();
        remove_stale_staging(&parent, &name, &host);
        check_existing(&shown, &real, force)?;
        me.staging = parent.join(format!(".{name}.partial-{host}-{pid}"));
        me.backup = parent.join(format!(".{name}.old-{host}-{pid}"));
        {
            let mut reg = registry();
            let c = reg.entry(id).or_default();
            c.trees.push(me.staging.clone());
            c.trees.push(me.backup.clone());
        }
        remove_tree(&me.staging);
        remove_tree(&me.backup);
        std::fs::create_dir(&me.staging).map_err(|e| io_at(&me.staging, "creating", e))?;
        Ok(me)
    }

    /// The staging path for a relative file name (parent folders created); record it.
    ///
    /// # Errors
    /// [`OutputError::UnsafePath`] for a name that is empty, absolute, or has `..`, `.`, a
    /// root, a prefix or NUL in it: nothing is ever written outside the staging directory.
    pub fn path(&mut self, rel: &str) -> Result<PathBuf, OutputError> {
        let rel = safe_relative(rel)?;
        // Under the registry lock: once the signal handler has started no folder is made, and
        // only below the staging directory (never the staging directory itself).
        let _reg = registry();
        let mut d = self.staging.clone();
        if let Some(parent) = rel.parent() {
            for c in parent.components() {
                d.push(c);
                match std::fs::create_dir(&d) {
                    Err(e) if e.kind() != ErrorKind::AlreadyExists => {
                        return Err(io_at(&d, "creating", e))
                    }
                    _ => {}
                }
            }
        }
        let p = self.staging.join(&rel);
        self.files.insert(rel);
        Ok(p)
    }

    /// Writes a whole file into the staging directory.
    ///
    /// # Errors
    /// As [`OutputDir::path`], or the write's I/O error.
    pub fn write(&mut self, rel: &str, bytes: impl AsRef<[u8]>) -> Result<(), OutputError> {
        let p = self.path(rel)?;
        std::fs::write(&p, bytes).map_err(|e| io_at(&p, "writing", e))
    }

    /// Adds the marker and swaps the complete folder in place of the target (the old one, if
    /// any, is removed as a whole); returns how many files were written (the marker aside).
    ///
    /// # Errors
    /// An I/O error; the old folder is then left (or put back) as it was.
    pub fn commit(mut self) -> Result<usize, OutputError> {
        let marker = self.staging.join(MARKER);
        std::fs::write(&marker, MARKER_TEXT).map_err(|e| io_at(&marker, "writing", e))?;
        {
            // Under the registry lock: a signal waits until the swap is complete.
            let mut reg = registry();
            let exists = std::fs::symlink_metadata(&self.target).is_ok();
            if exists {
                std::fs::rename(&self.target, &self.backup)
                    .map_err(|e| io_at(&self.shown, "moving aside", e))?;
            }
            if let Err(e) = std::fs::rename(&self.staging, &self.target) {
                if exists {
                    let _ = std::fs::rename(&self.backup, &self.target);
                }
                return Err(io_at(&self.shown, "moving into place", e));
            }
            // From here on the output is in place: a signal removes only the old folder.
            if let Some(c) = reg.get_mut(&self.id) {
                c.trees.retain(|t| *t == self.backup);
                c.parents.clear();
            }
            self.committed = true;
        }
        remove_tree(&self.backup);
        Ok(self.files.len())
    }
}

#[cfg(unix)]
fn same_device(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::MetadataExt;
    a.dev() == b.dev()
}

#[cfg(not(unix))]
fn same_device(_: &std::fs::Metadata, _: &std::fs::Metadata) -> bool {
    true
}

/// Takes the exclusive lock on `path` (waiting for another run), registering the lock file
/// for removal. The file is removed while locked when done; a waiter that then gets the lock
/// of the removed file sees that the path no longer names it and tries again.
/// This machine's name for the staging folders' names (Slurm nodes share storage: a PID means
/// something only on its own host): Linux's /proc/sys/kernel/hostname, else `$HOSTNAME`, else
/// "localhost"; characters other than ASCII letters, digits, '.' and '-' become '_'.
fn host_name() -> String {
    let raw = std::fs::read_to_string("/proc/sys/kernel/hostname")
        .ok()
        .or_else(|| std::env::var("HOSTNAME").ok())
        .map(|h| h.trim().to_string())
        .filter(|h| !h.is_empty())
        .unwrap_or_else(|| "localhost".into());
    raw.chars()
        .take(64)
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '.' | '-') {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Whether process `pid` of this host is alive: Linux's /proc; elsewhere every process is
/// taken as alive (nothing is removed).
fn alive(pid: u32) -> bool {
    if cfg!(target_os = "linux") {
        Path::new("/proc").join(pid.to_string()).exists()
    } else {
        true
    }
}

/// Cleans what a process of this host left beside the target when it was killed (SIGKILL,
/// SIGQUIT: no handler ran) and no live process owns: its staging folders
/// `.NAME.partial-HOST-PID` are removed; its backup `.NAME.old-HOST-PID` (the previous
/// output, moved aside while the new one was moved in) is put back as the target if the
/// target is missing — the kill fell between the two renames — and removed otherwise. Called
/// under the target's lock, so no live run of this target is staging; folders of other hosts
/// are left alone (their PIDs cannot be checked from here).
fn remove_stale_staging(parent: &Path, name: &str, host: &str) {
    let dead = |file: &std::ffi::OsStr, kind: &str| -> bool {
        let prefix = format!(".{name}.{kind}-{host}-");
        file.to_str()
            .and_then(|f| f.strip_prefix(&prefix))
            .and_then(|p| p.parse::<u32>().ok())
            .is_some_and(|pid| pid != std::process::id() && !alive(pid))
    };
    let Ok(entries) = std::fs::read_dir(parent) else {
        return;
    };
    let target = parent.join(name);
    for e in entries.flatten() {
        let file = e.file_name();
        if dead(&file, "partial") {
            remove_tree(&e.path());
        } else if dead(&file, "old") {
            if std::fs::symlink_metadata(&target).is_err() {
                let _ = std::fs::rename(e.path(), &target);
            } else {
                remove_tree(&e.path());
            }
        }
    }
}

fn lock(path: &Path, id: u64) -> Result<File, OutputError> {
    use fs4::fs_std::FileExt;
    loop {
        let f = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(path)
            .map_err(|e| io_at(path, "creating lock", e))?;
        FileExt::lock_exclusive(&f).map_err(|e| io_at(path, "locking", e))?;
        if same_file(&f, path) {
            registry().entry(id).or_default().lock_file = Some(path.to_path_buf());
            return Ok(f);
        }
    }
}

#[cfg(unix)]
fn same_file(f: &File, path: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (f.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

#[cfg(not(unix))]
fn same_file(_: &File, path: &Path) -> bool {
    path.exists()
}

impl Drop for OutputDir {
    fn drop(&mut self) {
        let mut reg = registry();
        if let Some(c) = reg.remove(&self.id) {
            if self.committed {
                // Only the lock file is left to remove (the backup is gone already).
                if let Some(l) = &c.lock_file {
                    let _ = std::fs::remove_file(l);
                }
            } else {
                c.run();
            }
        }
        drop(reg);
        // Closing the file releases the lock.
        self.lock.take();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hostile_relative_names_are_refused() {
        for bad in [
            "../x",
            "/etc/x",
            "a/../../x",
            "a\0b",
            "a/..",
            "..",
            "",
            "/",
            "./x",
            "plots/../../../etc/passwd",
        ] {
            assert!(
                matches!(safe_relative(bad), Err(OutputError::UnsafePath { .. })),
                "{bad:?} accepted"
            );
        }
        assert_eq!(safe_relative("a//b").unwrap(), PathBuf::from("a/b"));
        assert_eq!(
            safe_relative("plots/x.png").unwrap(),
            PathBuf::from("plots/x.png")
        );
    }

    #[test]
    fn hostile_names_write_nothing_outside_staging() {
        let root = std::env::temp_dir().join(format!("flexcraft-atomic-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&root);
        std::fs::create_dir_all(&root).unwrap();
        let target = root.join("out");
        let mut o = OutputDir::create(&target, false).unwrap();
        for bad in [
            "../x",
            "/tmp/flexcraft-evil",
            "a/../../x",
            "a\0b",
            "../../x/y",
        ] {
            assert!(
                matches!(o.write(bad, "evil"), Err(OutputError::UnsafePath { .. })),
                "{bad:?}"
            );
            assert!(matches!(o.path(bad), Err(OutputError::UnsafePath { .. })));
        }
        o.write("a/b.txt", "ok").unwrap();
        assert_eq!(o.commit().unwrap(), 1);
        assert!(!root.join("x").exists() && !Path::new("/tmp/flexcraft-evil").exists());
        let mut names: Vec<_> = std::fs::read_dir(&root)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(names, vec!["out"]);
        assert_eq!(std::fs::read(target.join("a/b.txt")).unwrap(), b"ok");
        assert!(target.join(MARKER).is_file());
        let _ = std::fs::remove_dir_all(&root);
    }
}
