//! The default scene, `scenes/das.toml`, built into the binary with the assets it reads, so
//! that a command whose scene has a default (`reproduce`) works outside the repository too.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

/// The repository's files, as `(path relative to the scene's root, bytes)`; das.toml names
/// its assets as `../assets/…`, so they keep their places.
const FILES: [(&str, &[u8]); 4] = [
    ("scenes/das.toml", include_bytes!("../../scenes/das.toml")),
    ("assets/car.obj", include_bytes!("../../assets/car.obj")),
    ("assets/car.mtl", include_bytes!("../../assets/car.mtl")),
    (
        "assets/street.png",
        include_bytes!("../../assets/street.png"),
    ),
];

/// The path the default scene is given by, relative to the current folder.
pub const DAS_PATH: &str = "scenes/das.toml";

/// A copy of the built-in das scene in a private temporary folder, removed when dropped.
pub struct BuiltinDas {
    root: PathBuf,
}

impl BuiltinDas {
    /// Writes the scene and its assets to a new folder under the system's temporary folder.
    pub fn write() -> Result<BuiltinDas> {
        let root = std::env::temp_dir().join(format!("seethru-builtin-das-{}", std::process::id()));
        // A folder left by a killed process of the same id is stale: start afresh.
        let _ = std::fs::remove_dir_all(&root);
        let builtin = BuiltinDas { root };
        for (name, bytes) in FILES {
            let path = builtin.root.join(name);
            std::fs::create_dir_all(path.parent().expect("a file in a folder"))
                .and_then(|()| std::fs::write(&path, bytes))
                .with_context(|| format!("{}: cannot write the built-in scene", path.display()))?;
        }
        Ok(builtin)
    }

    /// The scene file of the copy.
    pub fn scene(&self) -> PathBuf {
        self.root.join(DAS_PATH)
    }

    /// The copy's root folder (holding `scenes/` and `assets/`).
    pub fn root(&self) -> &Path {
        &self.root
    }
}

impl Drop for BuiltinDas {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.root);
    }
}
