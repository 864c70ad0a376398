//! What the binaries' end-to-end tests share: a scratch folder removed on drop.

use std::path::PathBuf;

/// A red square in front of a larger green-and-blue one (vertex colours), so a new view
/// shows parallax and uncovers some of the back square.
#[allow(dead_code)] // used by some of the test binaries that share this module
pub const TWO_SQUARES: &str = "\
v -0.5 -0.5 0.5 1 0 0
v 0.5 -0.5 0.5 1 0 0
v 0.5 0.5 0.5 1 0 0
v -0.5 0.5 0.5 1 0 0
v -2 -2 -1 0 1 0
v 2 -2 -1 0 0 1
v 2 2 -1 0 0 1
v -2 2 -1 0 1 0
f 1 2 3
f 1 3 4
f 5 6 7
f 5 7 8
";

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
