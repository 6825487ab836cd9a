//! An output directory written all-or-nothing: files go to a hidden staging directory beside
//! the target and are moved into place by [`OutputDir::commit`]; if anything fails (or the
//! value is dropped uncommitted) the staging directory is removed and the target is untouched.

use std::path::{Path, PathBuf};

/// A staged output directory.
#[derive(Debug)]
pub struct OutputDir {
    target: PathBuf,
    staging: PathBuf,
    files: Vec<PathBuf>,
    committed: bool,
}

impl OutputDir {
    /// Prepares a staging directory for `target` (which need not exist).
    pub fn create(target: &Path) -> std::io::Result<Self> {
        let parent = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let name = target
            .file_name()
            .map_or_else(|| "out".into(), |n| n.to_string_lossy().into_owned());
        std::fs::create_dir_all(&parent)?;
        let staging = parent.join(format!(".{name}.partial-{}", std::process::id()));
        if staging.exists() {
            std::fs::remove_dir_all(&staging)?;
        }
        std::fs::create_dir_all(&staging)?;
        Ok(Self {
            target: target.to_path_buf(),
            staging,
            files: Vec::new(),
            committed: false,
        })
    }

    /// The staging path for a relative file name (parent folders created); record it.
    pub fn path(&mut self, rel: &str) -> std::io::Result<PathBuf> {
        let p = self.staging.join(rel);
        if let Some(d) = p.parent() {
            std::fs::create_dir_all(d)?;
        }
        self.files.push(PathBuf::from(rel));
        Ok(p)
    }

    /// Writes a whole file into the staging directory.
    pub fn write(&mut self, rel: &str, bytes: impl AsRef<[u8]>) -> std::io::Result<()> {
        let p = self.path(rel)?;
        std::fs::write(p, bytes)
    }

    /// Moves every staged file into the target directory; returns how many.
    pub fn commit(mut self) -> std::io::Result<usize> {
        if !self.target.exists() {
            std::fs::rename(&self.staging, &self.target)?;
        } else {
            for f in &self.files {
                let dst = self.target.join(f);
                if let Some(d) = dst.parent() {
                    std::fs::create_dir_all(d)?;
                }
                std::fs::rename(self.staging.join(f), dst)?;
            }
            std::fs::remove_dir_all(&self.staging)?;
        }
        self.committed = true;
        Ok(self.files.len())
    }
}

impl Drop for OutputDir {
    fn drop(&mut self) {
        if !self.committed {
            let _ = std::fs::remove_dir_all(&self.staging);
        }
    }
}
