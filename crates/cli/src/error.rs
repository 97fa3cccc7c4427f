//! The command line's errors: each names what was wrong, and `main` prints
//! it and exits with a nonzero code.

use std::fmt;

use crate::scene_file::SceneFileError;

/// Everything a command can fail with.
#[derive(Debug)]
pub enum CliError {
    /// No built-in scene has this name (and no such file exists).
    UnknownScene {
        /// The name given.
        name: String,
        /// Built-in names close to it.
        suggestions: Vec<String>,
    },
    /// The scene needs the `portals` feature, built without it.
    NeedsPortals(String),
    /// A scene file that does not parse or does not build.
    SceneFile(SceneFileError),
    /// The world rejected something while building or stepping.
    World(String),
    /// A picture could not be made or written.
    Render(janus2d_render::RenderError),
    /// A file could not be read or written.
    Io {
        /// The file.
        path: String,
        /// What the system said.
        message: String,
    },
    /// An option out of range (`--threads 0`, `--size 0x0`, …).
    Invalid(String),
}

impl CliError {
    /// An I/O error on `path`.
    #[must_use]
    pub fn io(path: &std::path::Path, e: &std::io::Error) -> CliError {
        CliError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        }
    }
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CliError::UnknownScene { name, suggestions } => {
                write!(f, "no built-in scene or scene file `{name}`")?;
                if !suggestions.is_empty() {
                    write!(f, " (did you mean {}?)", suggestions.join(", "))?;
                }
                write!(f, "; `janus2d list` shows the scenes")
            }
            CliError::NeedsPortals(name) => {
                write!(
                    f,
                    "scene `{name}` has portals: build with the `portals` feature"
                )
            }
            CliError::SceneFile(e) => write!(f, "{e}"),
            CliError::World(m) => write!(f, "the world refused: {m}"),
            CliError::Render(e) => write!(f, "{e}"),
            CliError::Io { path, message } => write!(f, "{path}: {message}"),
            CliError::Invalid(m) => write!(f, "{m}"),
        }
    }
}

impl std::error::Error for CliError {}

impl From<SceneFileError> for CliError {
    fn from(e: SceneFileError) -> Self {
        CliError::SceneFile(e)
    }
}

impl From<janus2d_world::WorldError> for CliError {
    fn from(e: janus2d_world::WorldError) -> Self {
        CliError::World(format!("{e}"))
    }
}

impl From<janus2d_render::RenderError> for CliError {
    fn from(e: janus2d_render::RenderError) -> Self {
        CliError::Render(e)
    }
}
