//! What the binaries' end-to-end tests share: a scratch folder removed on drop.

use std::path::PathBuf;

/// A scratch folder under the system temp dir, removed on drop.
pub struct Tmp(PathBuf);

impl Tmp {
    /// `parallax-{suite}-{pid}-{name}` under the temp dir, emptied.
    pub fn new(suite: &str, name: &str) -> Tmp {
        let d =
            std::env::temp_dir().join(format!("parallax-{suite}-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        Tmp(d)
    }

    pub fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

impl Drop for Tmp {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
