//! The error type of every reader and writer.
//!
//! An error names the file (or the in-memory source), where in it the problem is
//! ([`Location`]: a 1-based line, an element index, a byte offset) and what is wrong
//! ([`ErrorKind`]).

use std::fmt;
use std::path::PathBuf;

/// Where in a file a problem was found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Location {
    /// Nowhere in particular (the whole file, or the file system).
    File,
    /// A 1-based line of a text file.
    Line(u64),
    /// An element of a named group, 0-based (`vertex` 12, `face` 3, `triangle` 7, `point` 9).
    Element {
        /// The element kind as the format names it (`vertex`, `face`, `tristrips`, `facet`…).
        kind: String,
        /// 0-based index of the element.
        index: u64,
    },
    /// A 0-based byte offset of a binary file.
    Byte(u64),
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::File => Ok(()),
            Location::Line(l) => write!(f, "line {l}"),
            Location::Element { kind, index } => write!(f, "{kind} {index}"),
            Location::Byte(b) => write!(f, "byte {b}"),
        }
    }
}

/// What is wrong.
#[derive(Debug, thiserror::Error)]
pub enum ErrorKind {
    /// The operating system refused (missing file, permission, disk full…).
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// The path is a directory.
    #[error("is a directory, not a file")]
    IsDirectory,
    /// The file holds no data at all (0 bytes, or only whitespace/comments).
    #[error("file is empty")]
    Empty,
    /// Neither the extension nor the content identifies a supported format.
    #[error("unknown file format{0}")]
    UnknownFormat(String),
    /// The header is malformed or contradicts itself.
    #[error("bad header: {0}")]
    BadHeader(String),
    /// The data ends before everything the header (or a count) announced.
    #[error("unexpected end of data: {0}")]
    Truncated(String),
    /// A count is impossible (negative, larger than the data could hold, or contradicted).
    #[error("bad count: {0}")]
    BadCount(String),
    /// A face refers to a vertex that does not exist.
    #[error("vertex index {index} out of range (the file has {count} vertices)")]
    IndexOutOfRange {
        /// The index as written (after resolving negative OBJ indices).
        index: i64,
        /// How many vertices there are.
        count: u64,
    },
    /// A coordinate or normal component is NaN or infinite.
    #[error("non-finite value ({0})")]
    NonFinite(String),
    /// A token could not be parsed or a statement is malformed.
    #[error("syntax error: {0}")]
    Syntax(String),
    /// Well-formed, but uses a feature subfit does not support.
    #[error("unsupported: {0}")]
    Unsupported(String),
    /// The data cannot be written in the requested format.
    #[error("cannot write: {0}")]
    CannotWrite(String),
}

/// An error from reading or writing a mesh file.
#[derive(Debug)]
pub struct Error {
    /// The file, or a label such as `<memory>` for in-memory input.
    pub path: PathBuf,
    /// Where in the file.
    pub location: Location,
    /// What is wrong.
    pub kind: ErrorKind,
}

impl Error {
    /// A new error.
    pub fn new(path: impl Into<PathBuf>, location: Location, kind: ErrorKind) -> Self {
        Self {
            path: path.into(),
            location,
            kind,
        }
    }

    /// An error at a 1-based line.
    pub fn at_line(path: impl Into<PathBuf>, line: u64, kind: ErrorKind) -> Self {
        Self::new(path, Location::Line(line), kind)
    }

    /// An error at a 0-based element index.
    pub fn at_element(
        path: impl Into<PathBuf>,
        kind_name: &str,
        index: u64,
        kind: ErrorKind,
    ) -> Self {
        Self::new(
            path,
            Location::Element {
                kind: kind_name.to_string(),
                index,
            },
            kind,
        )
    }

    /// An error about the whole file.
    pub fn file(path: impl Into<PathBuf>, kind: ErrorKind) -> Self {
        Self::new(path, Location::File, kind)
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.path.display())?;
        if self.location != Location::File {
            write!(f, ": {}", self.location)?;
        }
        write!(f, ": {}", self.kind)
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.kind {
            ErrorKind::Io(e) => Some(e),
            _ => None,
        }
    }
}

/// Result alias for this crate.
pub type Result<T, E = Error> = std::result::Result<T, E>;
