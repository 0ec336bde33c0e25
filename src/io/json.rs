//! JSON files people write by hand (experiments, scenes, shards): parse
//! errors name the field.
//!
//! serde_json names a field only when it is missing or unknown; a value of
//! the wrong type (`"sets": -2`) gets a line and column alone.
//! `serde_path_to_error` tracks the path of the value being read, so the
//! message says `sets: invalid value: integer -2, expected usize at line 1
//! column 80`.

use serde::de::DeserializeOwned;

/// Parses `text` as a `T`, a struct written as one JSON object.
///
/// # Errors
/// serde_json's message, prefixed with the path of the offending field
/// (`camera.resolution[0]`) when it lies below the top level, and made
/// plainer where serde_json's words mislead a person writing the file: a
/// top-level array (which serde would read as the struct's fields in
/// order), an array longer than its field takes ("trailing characters"),
/// and a value that is not JSON ("expected value"), named with `NaN` and
/// `Infinity` called out, which JSON does not have.
pub fn from_json<T: DeserializeOwned>(text: &str) -> Result<T, String> {
    const OBJECT: &str = "one JSON object ({ \"field\": value, ... })";
    let start = text.trim_start();
    match start.chars().next() {
        Some('{') => {}
        None => return Err(format!("empty, where {OBJECT} is expected")),
        Some('[') => return Err(format!("a JSON array, where {OBJECT} is expected")),
        Some(_) => {
            let found = start.split_whitespace().next().unwrap_or_default();
            let found: String = found.chars().take(24).collect();
            return Err(format!("`{found}` at the top, where {OBJECT} is expected"));
        }
    }
    let mut de = serde_json::Deserializer::from_str(text);
    let value: T = serde_path_to_error::deserialize(&mut de).map_err(|e| {
        // A last segment "?" is serde_path_to_error's unknown place (a
        // syntax error inside a tagged enum): keep the known part; the
        // message's line and column say where.
        let full = e.path().to_string();
        let path = full.trim_end_matches('?').trim_end_matches('.');
        let wrong_value = {
            let inner = e.inner().to_string();
            inner.starts_with("invalid type") || inner.starts_with("invalid value")
        };
        // Hand-written files only: the search parses the text again and
        // deserializes it once per key (a large table shard need not).
        if wrong_value
            && !path.is_empty()
            && text.len() <= LOCATE_LIMIT
            && let Some(located) = field_in_tagged_object::<T>(text, path)
        {
            return located;
        }
        if e.inner().to_string().starts_with("expected value")
            && !path.is_empty()
            && text.len() <= LOCATE_LIMIT
            && let Some(named) = name_expected::<T>(text, path, e.inner())
        {
            return format!("{path}: {named}");
        }
        let message = plain_message(e.inner(), text);
        if path.is_empty() {
            message
        } else {
            format!("{path}: {message}")
        }
    })?;
    de.end().map_err(|e| e.to_string())?;
    Ok(value)
}

/// The largest text whose wrong-typed field [`field_in_tagged_object`]
/// looks for (experiment and scene files are kilobytes).
const LOCATE_LIMIT: usize = 1 << 20;

/// The field of a wrong type inside an internally tagged enum's object
/// (`{"figure": "scene-samplers", "spp": [16]}`), whose fields serde reads
/// from a buffer the path tracking does not see: the error names only the
/// object (`figures[0]`) and the position of its end. The culprit is the
/// first key whose value is the one the error describes (`sequence`,
/// `string "x"`, `integer `-4``) and whose removal changes the error: the
/// entries are read in order and a wrong type stops the reading before any
/// missing field is noticed, so removing another key leaves the same error
/// (but the tag's, whose removal loses the variant; its value is a name,
/// not the value described). `None` when the error is not of that kind or
/// no key explains it.
fn field_in_tagged_object<T: DeserializeOwned>(text: &str, path: &str) -> Option<String> {
    let root: serde_json::Value = serde_json::from_str(text).ok()?;
    let error_of = |value: serde_json::Value| {
        serde_path_to_error::deserialize::<_, T>(value)
            .err()
            .map(|e| (e.path().to_string(), e.inner().to_string()))
    };
    let (original_path, original) = error_of(root.clone())?;
    if original_path.trim_end_matches(['?', '.']) != path {
        return None;
    }
    let pointer = json_pointer(path)?;
    let object = root.pointer(&pointer)?.as_object()?;
    object
        .iter()
        .filter(|(_, value)| {
            unexpected(value)
                .iter()
                .any(|words| original.contains(words.as_str()))
        })
        .find_map(|(key, _)| {
            let mut trial = root.clone();
            trial.pointer_mut(&pointer)?.as_object_mut()?.remove(key);
            (error_of(trial).map(|e| e.1) != Some(original.clone()))
                .then(|| format!("{path}.{key}: {original}"))
        })
}

/// serde_json's "expected value" in a text that is valid JSON: a name of
/// an enum (`"integrand": "lens"`) given as a number, array, boolean or
/// null, which serde_json's enum reader calls a syntax error. The names it
/// takes come from the error of the same text with `""` in that value's
/// place ("unknown variant ``, expected `lens` or `light`"; the text, not
/// a parsed map, so no other field is read first). `None` when the text is
/// not JSON (then the message is right) or no value starts there.
fn name_expected<T: DeserializeOwned>(
    text: &str,
    path: &str,
    error: &serde_json::Error,
) -> Option<String> {
    serde_json::from_str::<serde_json::Value>(text).ok()?;
    // The error's 1-based line and byte column as a byte offset.
    let line_start: usize = text
        .split_inclusive('\n')
        .take(error.line().saturating_sub(1))
        .map(str::len)
        .sum();
    let at = line_start + error.column().saturating_sub(1);
    let rest = text.get(at..)?;
    let mut values = serde_json::Deserializer::from_str(rest).into_iter::<serde_json::Value>();
    let value = values.next()?.ok()?;
    let (written, after) = rest.split_at(values.byte_offset());
    let found = match value {
        serde_json::Value::Array(_) => "an array".to_string(),
        serde_json::Value::Object(_) | serde_json::Value::String(_) => return None,
        _ => format!("`{}`", written.trim()),
    };
    let replaced = format!("{}\"\"{after}", &text[..at]);
    let mut de = serde_json::Deserializer::from_str(&replaced);
    let names = serde_path_to_error::deserialize::<_, T>(&mut de)
        .err()
        .and_then(|e| {
            let inner = e.inner().to_string();
            (e.path().to_string() == path)
                .then(|| {
                    inner
                        .strip_prefix("unknown variant ``, expected ")
                        .and_then(|names| names.split(" at line ").next())
                        .map(|names| format!(": {names}"))
                })
                .flatten()
        })
        .unwrap_or_default();
    Some(format!(
        "{found} where a name (a JSON string) is expected{names} at line {} column {}",
        error.line(),
        error.column()
    ))
}

/// How serde's "invalid type" and "invalid value" errors may describe a
/// JSON value (serde::de::Unexpected's wording; null reads `null` from
/// serde_json and `unit value` from a buffered tagged enum).
fn unexpected(value: &serde_json::Value) -> Vec<String> {
    use serde_json::Value;
    match value {
        Value::Null => vec!["null".into(), "unit value".into()],
        Value::Bool(b) => vec![format!("boolean `{b}`")],
        Value::Number(n) if n.is_f64() => vec![format!("floating point `{n}`")],
        Value::Number(n) => vec![format!("integer `{n}`")],
        Value::String(s) => vec![format!("string {s:?}")],
        Value::Array(_) => vec!["sequence".into()],
        Value::Object(_) => vec!["map".into()],
    }
}

/// A serde_path_to_error path (`figures[0].scene`) as a JSON pointer
/// (`/figures/0/scene`); `None` for a path with an unknown segment.
fn json_pointer(path: &str) -> Option<String> {
    let mut pointer = String::new();
    for part in path.split('.').filter(|p| !p.is_empty()) {
        let (name, indices) = part.split_once('[').map_or((part, ""), |(n, i)| (n, i));
        if name == "?" {
            return None;
        }
        if !name.is_empty() {
            pointer += &format!("/{}", name.replace('~', "~0").replace('/', "~1"));
        }
        for index in indices.split('[').filter(|i| !i.is_empty()) {
            pointer += &format!("/{}", index.trim_end_matches(']'));
        }
    }
    Some(pointer)
}

/// serde_json's message for an error below the top level, in a file
/// writer's words where serde_json's own mislead.
fn plain_message(e: &serde_json::Error, text: &str) -> String {
    let at = format!("at line {} column {}", e.line(), e.column());
    let message = e.to_string();
    if message.starts_with("trailing characters") {
        // Inside a value, serde_json says this of a fixed-length array
        // given more elements than it takes.
        return format!("more elements than this array takes {at}");
    }
    if message.starts_with("expected value") || message.starts_with("invalid number") {
        let found = token_at(text, e.line(), e.column());
        if found.is_empty() {
            return message;
        }
        let bare = found.trim_start_matches(['+', '-']).to_ascii_lowercase();
        let hint = if ["nan", "inf", "infinity"].contains(&bare.as_str()) {
            " (JSON has no NaN or infinities: give a finite number)"
        } else {
            ""
        };
        return format!("`{found}` is not a JSON value{hint} {at}");
    }
    message
}

/// The word around 1-based `line` and `column` of `text` (letters,
/// digits, signs and dots), empty if there is none.
fn token_at(text: &str, line: usize, column: usize) -> &str {
    let part = |c: char| c.is_alphanumeric() || matches!(c, '+' | '-' | '.');
    let Some(row) = text.lines().nth(line.saturating_sub(1)) else {
        return "";
    };
    let Some((before, after)) = row.split_at_checked(column.saturating_sub(1).min(row.len()))
    else {
        return "";
    };
    let start = before.rfind(|c: char| !part(c)).map_or(0, |i| i + 1);
    let end = after.find(|c: char| !part(c)).unwrap_or(after.len());
    &row[start..before.len() + end]
}

#[cfg(test)]
mod tests {
    use super::token_at;

    #[test]
    fn the_word_around_an_error_s_column_is_found_whole() {
        let text = "{\n  \"a\": -Infinity,\n  \"é\": NaN }";
        // serde_json points at the sign's successor for an invalid number
        // and at the first letter for a value it does not know.
        assert_eq!(token_at(text, 2, 9), "-Infinity");
        assert_eq!(token_at(text, 2, 8), "-Infinity");
        // Columns count bytes: "é" is two, so NaN starts at byte 9.
        assert_eq!(token_at(text, 3, 9), "NaN");
        // Inside a multi-byte character, past the end, or on a missing
        // line: nothing, never a panic.
        assert_eq!(token_at(text, 3, 5), "");
        assert_eq!(token_at(text, 2, 400), "");
        assert_eq!(token_at(text, 9, 1), "");
    }
}
