//! Dataset folders in the EuRoC / ASL layout (see the contract): writing a simulated one, and
//! reading any one as a time-ordered stream of sensor events with constant memory.
//!
//! Errors name the file and the line, in one line: `imu0/data.csv:17: expected 7 columns, got 6`.

pub mod read;
pub mod write;
pub mod yaml;

use std::path::{Path, PathBuf};

/// An error reading or writing a dataset: where, and what.
#[derive(Debug, thiserror::Error)]
pub enum DatasetError {
    /// A problem at a line of a file.
    #[error("{}:{line}: {message}", path.display())]
    At {
        /// The file.
        path: PathBuf,
        /// 1-based line number.
        line: u64,
        /// What is wrong.
        message: String,
    },
    /// A problem with a whole file (missing, unreadable).
    #[error("{}: {message}", path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
}

impl DatasetError {
    pub(crate) fn at(path: &Path, line: u64, message: impl Into<String>) -> Self {
        Self::At {
            path: path.to_path_buf(),
            line,
            message: message.into(),
        }
    }

    pub(crate) fn file(path: &Path, message: impl std::fmt::Display) -> Self {
        Self::File {
            path: path.to_path_buf(),
            message: message.to_string(),
        }
    }
}
