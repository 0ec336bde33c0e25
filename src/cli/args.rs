//! Argument value parsers shared by subcommands.

use anyhow::{Context, bail};

/// Parses `key=value`.
pub fn key_value(text: &str) -> Result<(String, String), String> {
    match text.split_once('=') {
        Some((k, v)) if !k.trim().is_empty() => Ok((k.trim().to_string(), v.trim().to_string())),
        _ => Err(format!("`{text}` is not of the form key=value")),
    }
}

/// Parses a list of dimension indices such as `0,2`, requiring `count` of them.
pub fn dims(text: &str, count: usize) -> anyhow::Result<Vec<usize>> {
    let dims = text
        .split(',')
        .map(|t| t.trim().parse::<usize>())
        .collect::<Result<Vec<_>, _>>()
        .with_context(|| {
            if count == 1 {
                format!("--dims `{text}`: expected an index such as 0")
            } else {
                format!("--dims `{text}`: expected {count} comma-separated indices such as 0,2")
            }
        })?;
    if dims.len() != count {
        bail!(
            "--dims `{text}`: expected {count} indices, found {}",
            dims.len()
        );
    }
    Ok(dims)
}

/// A relative NUFFT tolerance: a number in [1e-14, 0.1] (the range every
/// plan accepts), checked when given even where a method does not use it.
pub fn tolerance(text: &str) -> Result<f64, String> {
    text.parse::<f64>()
        .ok()
        .filter(|t| (1e-14..=0.1).contains(t))
        .ok_or_else(|| format!("`{text}`: a relative tolerance is a number from 1e-14 to 0.1"))
}

/// Family members scored when --members is not given.
pub const DEFAULT_MEMBERS: usize = 1024;

/// --members checked against --family: it only applies there.
pub fn family_members(members: Option<usize>, family: Option<&str>) -> anyhow::Result<usize> {
    match (members, family) {
        (Some(_), None) => {
            bail!("--members applies to --family (a family's members), not to --integrand")
        }
        (m, _) => Ok(m.unwrap_or(DEFAULT_MEMBERS)),
    }
}

/// Realizations drawn when --sets is not given, the same in every command
/// that draws sets of a sampler (sample, predict, converge, spectrum, pcf,
/// optimize points, tables).
pub const DEFAULT_SETS: usize = 16;

/// How realizations of a sampler are drawn: how many, from which seed, with
/// which sampler parameters (shared by the commands that draw sets).
#[derive(clap::Args)]
pub struct DrawArgs {
    /// Realizations to draw (with a sampler; default 16; without it,
    /// `predict` alone draws more when 16 leave its standard error above 5%
    /// of the variance).
    #[arg(value_parser = whole_at_least::<1, usize>, allow_negative_numbers = true, long = "sets", value_name = "SETS")]
    sets_given: Option<usize>,
    /// Seed (default 0): the same seed gives bit-identical realizations
    /// for any thread count.
    #[arg(value_parser = whole::<u64>, allow_negative_numbers = true, long = "seed", value_name = "SEED")]
    seed_given: Option<u64>,
    /// Sampler parameter key=value (repeatable; see `varspec sample --list`;
    /// wins over the same key in the NAME:key=value shorthand).
    #[arg(long = "param", value_parser = key_value)]
    pub params: Vec<(String, String)>,
}

impl DrawArgs {
    /// The seed: --seed, default 0.
    pub fn seed(&self) -> u64 {
        self.seed_given.unwrap_or(0)
    }

    /// Whether --seed was given (a command where it would do nothing
    /// refuses it).
    pub fn seed_was_given(&self) -> bool {
        self.seed_given.is_some()
    }

    /// Whether --sets was given (a command may choose the count itself
    /// otherwise).
    pub fn sets_were_given(&self) -> bool {
        self.sets_given.is_some()
    }

    /// Realizations to draw: --sets, default [`DEFAULT_SETS`].
    pub fn sets(&self) -> usize {
        self.sets_given.unwrap_or(DEFAULT_SETS)
    }

    /// Refuses more sets than the machine can hold results for: analyses
    /// draw sets one at a time but keep a few numbers per set (estimates,
    /// sums), 64 bytes an ample bound.
    pub fn check_results_memory(&self) -> anyhow::Result<()> {
        varspec::memory::check(
            &format!("the per-set results of {} realizations", self.sets()),
            Some(self.sets() as f64 * 64.0),
            "lower --sets",
        )?;
        Ok(())
    }

    /// Refuses --sets and --param where sets come from a file (they would
    /// be silently ignored).
    /// `seed_used`: the command draws something else from --seed with a
    /// file (a family's members), so --seed is not refused.
    pub fn refuse_with_file(&self, file: &std::path::Path, seed_used: bool) -> anyhow::Result<()> {
        if self.sets_given.is_some() || !self.params.is_empty() {
            anyhow::bail!(
                "--sets and --param apply to --sampler; {} is read whole, every set in it is used",
                file.display()
            );
        }
        if self.seed_given.is_some() && !seed_used {
            anyhow::bail!(
                "--seed applies to --sampler; {} holds fixed sets, so a seed would change nothing",
                file.display()
            );
        }
        Ok(())
    }
}

/// A path for a file written in one format: a name whose extension says
/// another is refused rather than filled with `what`'s bytes (`--png
/// s.csv`, `--pfm out.exr`); no extension (`/dev/null`) is fine. `refused`
/// says which extensions: every one but `ext`, or only those listed.
fn path_for(
    text: &str,
    ext: &str,
    what: &str,
    refused: Option<&[&str]>,
) -> Result<std::path::PathBuf, String> {
    if text.is_empty() {
        return Err(format!(
            "an empty file name: name the {what} file, e.g. out.{ext}"
        ));
    }
    let path = std::path::PathBuf::from(text);
    match path.extension().map(|e| e.to_string_lossy().to_lowercase()) {
        Some(given)
            if given != ext && refused.is_none_or(|list| list.contains(&given.as_str())) =>
        {
            Err(format!(
                "`{text}`: a {what} is written here (not .{given}); name the file .{ext}"
            ))
        }
        _ => Ok(path),
    }
}

/// A picture's path, written as PNG ([`path_for`]).
///
/// # Errors
/// A sentence naming the path.
pub fn png_path(text: &str) -> Result<std::path::PathBuf, String> {
    path_for(text, "png", "PNG picture", None)
}

/// A float image's path, written as PFM ([`path_for`]; `--pfm out.exr`
/// wrote a PFM under an OpenEXR name).
///
/// # Errors
/// A sentence naming the path.
pub fn pfm_path(text: &str) -> Result<std::path::PathBuf, String> {
    path_for(text, "pfm", "PFM float image", None)
}

/// A NumPy array's path, written as .npy ([`path_for`]).
///
/// # Errors
/// A sentence naming the path.
pub fn npy_path(text: &str) -> Result<std::path::PathBuf, String> {
    path_for(text, "npy", "NumPy .npy array", None)
}

/// Extensions of formats a file of another format must not carry (the
/// tool's own and the usual pictures and documents); a name ending in
/// another (`.txt`, `.dat`, `.f32`) is left to the user.
pub const KNOWN_FORMATS: [&str; 14] = [
    "csv", "npy", "npz", "png", "jpg", "jpeg", "pfm", "exr", "json", "pdf", "svg", "h", "hpp",
    "html",
];

/// A CSV table's path ([`path_for`]): `--csv r.png` wrote CSV under a
/// picture's name.
///
/// # Errors
/// A sentence naming the path.
pub fn csv_path(text: &str) -> Result<std::path::PathBuf, String> {
    path_for(text, "csv", "CSV table", Some(&KNOWN_FORMATS))
}

/// A JSON document's path ([`path_for`]): `--report r.csv` wrote JSON
/// under a table's name.
///
/// # Errors
/// A sentence naming the path.
pub fn json_path(text: &str) -> Result<std::path::PathBuf, String> {
    path_for(text, "json", "JSON document", Some(&KNOWN_FORMATS))
}

/// Refuses an output `path` whose extension names another format than
/// those in `own` (`what` is written there): for outputs whose format is
/// an option, checked once it is known.
///
/// # Errors
/// A sentence naming the path and the format.
pub fn check_extension(path: &std::path::Path, own: &[&str], what: &str) -> anyhow::Result<()> {
    let given = path.extension().map(|e| e.to_string_lossy().to_lowercase());
    match given {
        Some(given)
            if KNOWN_FORMATS.contains(&given.as_str()) && !own.contains(&given.as_str()) =>
        {
            anyhow::bail!(
                "`{}`: {what} is written here (not .{given}); {}",
                path.display(),
                match own.first() {
                    Some(ext) => format!("name the file .{ext}"),
                    None => "name the file without a format's extension (e.g. .bin)".into(),
                }
            )
        }
        _ => Ok(()),
    }
}

/// A point-set file's path: CSV, or NumPy .npy when the name ends in .npy
/// (any other name is CSV: `.txt`, `.dat`). A name whose extension says
/// another format (`t.npz`, `t.png`, `t.json`) would get CSV text under it,
/// and is refused.
///
/// # Errors
/// A sentence naming the path.
pub fn point_file_path(text: &str) -> Result<std::path::PathBuf, String> {
    const OTHER_FORMATS: [&str; 10] = [
        "npz", "png", "jpg", "jpeg", "pfm", "exr", "json", "pdf", "svg", "h",
    ];
    path_for(
        text,
        "csv",
        "point-set CSV (or NumPy .npy, by the name)",
        Some(&OTHER_FORMATS),
    )
}

/// Refuses an output folder `path` (named by `option`) that is an existing
/// file, before any work: a command that makes its folder only once it has
/// something to write checks this first.
///
/// # Errors
/// `path` is a file.
pub fn check_folder(path: &std::path::Path, option: &str) -> anyhow::Result<()> {
    if path.exists() && !path.is_dir() {
        bail!(
            "{option} {}: it is a file; give a folder (it is created if missing)",
            path.display()
        );
    }
    Ok(())
}

/// Creates the output folder `path` (any depth), named by `option`: an
/// existing file of that name is refused as such (the file system's
/// "File exists" named neither the option nor the problem).
///
/// # Errors
/// `path` is a file, or the folder cannot be created.
pub fn create_folder(path: &std::path::Path, option: &str) -> anyhow::Result<()> {
    check_folder(path, option)?;
    std::fs::create_dir_all(path)
        .with_context(|| format!("{option} {}: cannot create the folder", path.display()))
}

/// Checks every output before any work starts (a missing folder, a folder
/// given as a file), so a long run does not end in a failed write.
///
/// # Errors
/// The first output that cannot be written, or the same file given as two
/// outputs (one would silently replace the other).
pub fn check_outputs<'a>(
    paths: impl IntoIterator<Item = Option<&'a std::path::Path>>,
) -> anyhow::Result<()> {
    check_outputs_beside(paths, [])
}

/// [`check_outputs`], and that no output is one of the command's `inputs`
/// (writing it would replace the file being read).
///
/// # Errors
/// As [`check_outputs`], or an output that is an input.
pub fn check_outputs_beside<'a>(
    outputs: impl IntoIterator<Item = Option<&'a std::path::Path>>,
    inputs: impl IntoIterator<Item = Option<&'a std::path::Path>>,
) -> anyhow::Result<()> {
    let inputs: Vec<_> = inputs
        .into_iter()
        .flatten()
        .filter_map(|p| varspec::io::file_identity(p).map(|id| (p, id)))
        .collect();
    let mut seen: Vec<(&std::path::Path, std::path::PathBuf)> = Vec::new();
    for path in outputs.into_iter().flatten() {
        // Pictures are PNG whatever the name: a .jpg name would hold PNG bytes.
        if let Some(ext) = path.extension().map(|e| e.to_string_lossy().to_lowercase())
            && ["jpg", "jpeg", "gif", "bmp", "tif", "tiff", "webp"].contains(&ext.as_str())
        {
            anyhow::bail!(
                "{}: varspec writes pictures as PNG only; name the file .png",
                path.display()
            );
        }
        varspec::io::check_output(path)?;
        if varspec::io::is_standard_output(path) {
            super::stdout::carries_data();
        }
        let Some(id) = varspec::io::file_identity(path) else {
            continue;
        };
        let named = |other: &std::path::Path| {
            if other == path {
                format!("{}", path.display())
            } else {
                format!("{} (the same file as {})", path.display(), other.display())
            }
        };
        if let Some((input, _)) = inputs.iter().find(|(_, i)| *i == id) {
            bail!(
                "{} is both an input and an output of this command: writing it would replace what is read; name another output file",
                named(input)
            );
        }
        if let Some((other, _)) = seen.iter().find(|(_, s)| *s == id) {
            bail!(
                "{} is given as two outputs: one would replace the other; give each output its own file",
                named(other)
            );
        }
        seen.push((path, id));
    }
    Ok(())
}

/// Why a text is not a whole number.
enum NotWhole {
    Negative,
    Fraction,
    TooLarge,
    Text,
}

/// A whole number ≥ 0 written plainly (16) or in scientific notation when
/// that is whole (1e3): what [`whole`] and [`count`] share.
fn parse_whole(text: &str) -> Result<u64, NotWhole> {
    if let Ok(v) = text.parse::<u64>() {
        return Ok(v);
    }
    match text.parse::<f64>() {
        Ok(v) if v < 0.0 => Err(NotWhole::Negative),
        Ok(v) if !v.is_finite() || v.fract() != 0.0 => Err(NotWhole::Fraction),
        // 2^64 is exactly representable; below it the cast is exact for
        // every whole f64.
        Ok(v) if v < 18_446_744_073_709_551_616.0 => Ok(v as u64),
        Ok(_) => Err(NotWhole::TooLarge),
        Err(_) => Err(NotWhole::Text),
    }
}

/// A whole number ≥ 0 for counts, sizes and seeds, written plainly (16)
/// or in scientific notation when that is whole (1e3); negative,
/// fractional and too large values are refused naming what was typed
/// (clap's own parser says "invalid digit found in string").
pub fn whole<T: TryFrom<u64>>(text: &str) -> Result<T, String> {
    whole_at_least::<0, T>(text)
}

/// A Fourier box --res K: a whole number ≥ 3, the smallest box |k| < K/2
/// that holds a frequency besides k = 0 (one message for 0 and for −4).
pub fn frequency_box(text: &str) -> Result<usize, String> {
    match parse_whole(text) {
        Ok(k) if k >= 3 => usize::try_from(k).map_err(|_| format!("`{text}` is too large")),
        Ok(_) | Err(NotWhole::Negative) => Err(format!(
            "`{text}`: the box |k| < K/2 needs a whole K >= 3 to hold a frequency besides k = 0"
        )),
        Err(_) => whole::<usize>(text),
    }
}

/// A whole number of at least `MIN`, as [`whole`].
pub fn whole_at_least<const MIN: u64, T: TryFrom<u64>>(text: &str) -> Result<T, String> {
    whole_in::<MIN, { u64::MAX }, T>(text)
}

/// A whole number in [`MIN`, `MAX`], as [`whole`].
pub fn whole_in<const MIN: u64, const MAX: u64, T: TryFrom<u64>>(text: &str) -> Result<T, String> {
    let value = parse_whole(text).map_err(|e| match e {
        NotWhole::Negative => format!("`{text}` is negative; expected a whole number >= {MIN}"),
        NotWhole::Fraction => format!("`{text}` is not a whole number"),
        NotWhole::TooLarge => format!("`{text}` is larger than 2^64 - 1"),
        NotWhole::Text => format!("`{text}` is not a whole number (write e.g. 16 or 1e3)"),
    })?;
    if value < MIN {
        return Err(format!("`{text}`: expected a whole number >= {MIN}"));
    }
    if value > MAX {
        return Err(format!("`{text}`: expected a whole number <= {MAX}"));
    }
    T::try_from(value).map_err(|_| format!("`{text}` is too large for this option"))
}

/// A point count N: a whole number ≥ 1, written plainly (1024) or in
/// scientific notation when that is whole (1e6, 2.5e5); negative, fractional
/// and huge values are refused with what was typed.
pub fn count(text: &str) -> Result<usize, String> {
    let too_many =
        || format!("`{text}` is more points than this tool holds (fewer than 2^32 coordinates)");
    match parse_whole(text) {
        Ok(0) => Err("a count of points must be at least 1".into()),
        // Written plainly, any usize passes here (the sampler refuses what
        // it cannot hold); in scientific notation, below 2^52.
        Ok(v) if v < 1 << 52 || text.parse::<usize>().is_ok() => {
            usize::try_from(v).map_err(|_| too_many())
        }
        Ok(_) | Err(NotWhole::TooLarge) => Err(too_many()),
        Err(NotWhole::Negative) => Err(format!(
            "`{text}` is negative; a count of points is a whole number >= 1"
        )),
        Err(NotWhole::Fraction) => Err(format!("`{text}` is not a whole number of points")),
        Err(NotWhole::Text) => Err(format!(
            "`{text}` is not a count of points (a whole number such as 1024 or 1e6)"
        )),
    }
}

/// A Fourier form's truncation bound above this fraction of its value is
/// named (predict, converge).
pub const LOOSE_TRUNCATION: f64 = 0.1;

/// Why `--res` does nothing to a lattice's expected variance
/// (`variance::ClosedForm::Lattice`).
pub const LATTICE_HAS_NO_BOX: &str = "--res is not used: the expected variance of a shifted \
     lattice is the exact lattice sum, which has no frequency box";

/// Why a Fourier box's tail estimate can be far off, for the notes that
/// name a loose truncation bound.
pub const NOT_WHITE_BEYOND_THE_BOX: &str = "beyond the Fourier box the spectrum is not white \
     (an axis-aligned edge against N-rooks strata, a lattice's dual points, a spectrum still \
     rising)";

/// Prints a sampler's caveat ([`varspec::samplers::Sampler::caveat`]) as a
/// note on standard error; whether it had one.
pub fn note_caveat(sampler: &dyn varspec::samplers::Sampler) -> bool {
    let caveat = sampler.caveat();
    if let Some(c) = &caveat {
        eprintln!("note: {c}");
    }
    caveat.is_some()
}
