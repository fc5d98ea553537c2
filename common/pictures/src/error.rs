//! The pictures' error type. The messages name the file (tests quote them).

use std::path::PathBuf;

/// What keeps a picture from being written.
#[derive(Debug, thiserror::Error)]
pub enum PicturesError {
    /// A picture without pixels (no PNG can hold it).
    #[error("empty picture ({width} x {height})")]
    Empty { width: u32, height: u32 },
    /// The PNG could not be written; the source says why (an empty picture, the file, the
    /// encoder).
    #[error("cannot write the PNG {}", path.display())]
    WritePng {
        path: PathBuf,
        #[source]
        source: Box<dyn std::error::Error + Send + Sync>,
    },
}
