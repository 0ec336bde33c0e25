//! JSON files people write by hand (experiments, scenes, shards): parse
//! errors name the field.
//!
//! serde_json names a field only when it is missing or unknown; a value of
//! the wrong type (`"sets": -2`) gets a line and column alone.
//! `serde_path_to_error` tracks the path of the value being read, so the
//! message says `sets: invalid value: integer -2, expected usize at line 1
//! column 80`.

use serde::de::DeserializeOwned;

/// Parses `text` as a `T`.
///
/// # Errors
/// serde_json's message, prefixed with the path of the offending field
/// (`camera.resolution[0]`) when it lies below the top level.
pub fn from_json<T: DeserializeOwned>(text: &str) -> Result<T, String> {
    let mut de = serde_json::Deserializer::from_str(text);
    let value: T = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        let path = e.path().to_string();
        if path == "." {
            e.inner().to_string()
        } else {
            format!("{path}: {}", e.inner())
        }
    })?;
    de.end().map_err(|e| e.to_string())?;
    Ok(value)
}
