//! Shard files of split runs (`experiment --shard i/n`, `tables --shard
//! i/n`): each shard writes `{prefix}{i}-of-{n}.json`, and a merge finds
//! every such file in one folder and reads them back, in name order.

use std::path::{Path, PathBuf};

use serde::de::DeserializeOwned;

/// Why the shard files of a merge could not be read.
#[derive(Debug, thiserror::Error)]
pub enum ShardFilesError {
    /// The folder cannot be listed.
    #[error("cannot read folder {folder}: {cause}")]
    Folder {
        /// The folder.
        folder: PathBuf,
        /// The I/O error.
        cause: std::io::Error,
    },
    /// No file of the pattern.
    #[error("no {prefix}i-of-n.json files in {folder} to merge (write them with --shard i/n)")]
    None {
        /// The folder.
        folder: PathBuf,
        /// The name's prefix.
        prefix: String,
    },
    /// A file that cannot be read or is not a shard.
    #[error("{path}: not {what}: {reason}")]
    File {
        /// The file.
        path: PathBuf,
        /// What a shard file holds.
        what: String,
        /// Why.
        reason: String,
    },
    /// A shard file whose name is another shard's.
    #[error(
        "{path}: it holds shard {index}/{count}, whose file is {name}: a shard file was copied \
         or renamed"
    )]
    Misnamed {
        /// The file.
        path: PathBuf,
        /// The shard it holds.
        index: usize,
        /// Of how many.
        count: usize,
        /// That shard's file name.
        name: String,
    },
}

/// The name of shard `index` of `count` under `prefix`.
pub fn shard_file_name(prefix: &str, index: usize, count: usize) -> String {
    format!("{prefix}{index}-of-{count}.json")
}

/// Every `{prefix}*.json` in `folder`, in name order, each read (at most
/// `limit` bytes, described as `what` in errors) and parsed as `T`, whose
/// shard (index, count) `shard_of` gives must be the one its file name
/// says (a shard file copied or renamed is refused by name, rather than
/// reported later as a shard given twice).
///
/// # Errors
/// [`ShardFilesError`] naming the folder or the file.
pub fn read_shard_files<T: DeserializeOwned>(
    folder: &Path,
    prefix: &str,
    limit: u64,
    what: &str,
    shard_of: impl Fn(&T) -> (usize, usize),
) -> Result<Vec<T>, ShardFilesError> {
    let entries = std::fs::read_dir(folder).map_err(|cause| ShardFilesError::Folder {
        folder: folder.to_path_buf(),
        cause,
    })?;
    let mut paths: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with(prefix) && n.ends_with(".json"))
        })
        .collect();
    paths.sort();
    if paths.is_empty() {
        return Err(ShardFilesError::None {
            folder: folder.to_path_buf(),
            prefix: prefix.to_string(),
        });
    }
    paths
        .into_iter()
        .map(|path| {
            let fail = |reason: String| ShardFilesError::File {
                path: path.clone(),
                what: what.to_string(),
                reason,
            };
            let text =
                super::read_text_bounded(&path, limit, what).map_err(|e| fail(e.to_string()))?;
            let shard: T = super::from_json(&text).map_err(fail)?;
            let (index, count) = shard_of(&shard);
            let name = shard_file_name(prefix, index, count);
            if path.file_name().and_then(|n| n.to_str()) != Some(name.as_str()) {
                return Err(ShardFilesError::Misnamed {
                    path: path.clone(),
                    index,
                    count,
                    name,
                });
            }
            Ok(shard)
        })
        .collect()
}
