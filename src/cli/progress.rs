//! Progress bars: drawn on a terminal's stderr. Off a terminal (pipes, CI
//! logs, batch jobs) long work still reports: a line on stderr every
//! [`LOG_EVERY`] while it runs, so a job's log says how far it got and how
//! long is left.

use std::io::IsTerminal;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressStyle};

/// Interval of the progress lines written off a terminal (the first after
/// this long: work that ends sooner writes none), unless
/// `VARSPEC_PROGRESS_SECONDS` sets another (0: no lines).
const LOG_EVERY: Duration = Duration::from_secs(60);

/// The interval of the progress lines off a terminal: `LOG_EVERY`, or
/// `VARSPEC_PROGRESS_SECONDS` when it holds whole seconds (`None` for 0).
fn log_every() -> Option<Duration> {
    match std::env::var("VARSPEC_PROGRESS_SECONDS")
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok())
    {
        Some(0) => None,
        Some(seconds) => Some(Duration::from_secs(seconds)),
        None => Some(LOG_EVERY),
    }
}

/// A bar over `len` steps labelled `what`; off a terminal, a hidden bar
/// whose progress is logged (see the module docs); hidden for work too
/// small to watch.
pub fn bar(len: u64, what: &str) -> ProgressBar {
    counted_bar(len, what, Shown::Steps)
}

/// [`bar`] over work measured in units of unequal steps (pair evaluations,
/// points): it shows the percentage done, and its time left follows the
/// work rather than the step count.
pub fn share_bar(work: u64, what: &str) -> ProgressBar {
    counted_bar(work, what, Shown::Percent)
}

/// How a bar's progress reads.
#[derive(Clone, Copy)]
enum Shown {
    /// "3/16".
    Steps,
    /// "42%".
    Percent,
    /// The bar's current message (a spinner's stage) and the time alone.
    Elapsed,
}

fn counted_bar(len: u64, what: &str, shown: Shown) -> ProgressBar {
    if len < 2 {
        return ProgressBar::hidden();
    }
    if !std::io::stderr().is_terminal() {
        let bar = ProgressBar::hidden();
        bar.set_length(len);
        if let Some(every) = log_every() {
            log_while_running(&bar, what.to_string(), every, shown);
        }
        return bar;
    }
    let bar = ProgressBar::new(len);
    bar.set_style(style(shown).progress_chars("=> "));
    bar.set_message(what.to_string());
    bar
}

/// How a bar of each kind is drawn on a terminal.
fn style(shown: Shown) -> ProgressStyle {
    ProgressStyle::with_template(match shown {
        Shown::Steps => "{msg} [{bar:40}] {pos}/{len} ({eta} left)",
        Shown::Percent => "{msg} [{bar:40}] {percent}% ({eta} left)",
        Shown::Elapsed => "{spinner} {msg} ({elapsed})",
    })
    .expect("static template")
}

/// A spinner with the elapsed time for work of unknown length labelled
/// `what` (its message, which the work may change to name its stage); off
/// a terminal, a hidden one whose message and elapsed time are logged (see
/// the module docs). Finish it with `finish_and_clear`.
pub fn spinner(what: &str) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        let spinner = ProgressBar::hidden();
        spinner.set_message(what.to_string());
        if let Some(every) = log_every() {
            log_while_running(&spinner, what.to_string(), every, Shown::Elapsed);
        }
        return spinner;
    }
    let spinner = ProgressBar::new_spinner();
    spinner.set_style(style(Shown::Elapsed));
    spinner.set_message(what.to_string());
    spinner.enable_steady_tick(std::time::Duration::from_millis(200));
    spinner
}

/// Writes "varspec: WHAT: pos of len (or P% done) after …, about … left" on stderr
/// `every` so long until `bar` is finished or dropped, from a thread of
/// its own that holds only a weak reference.
fn log_while_running(bar: &ProgressBar, what: String, every: Duration, shown: Shown) {
    let weak = bar.downgrade();
    let started = Instant::now();
    std::thread::spawn(move || {
        let mut next = every;
        loop {
            std::thread::sleep(every.min(Duration::from_secs(1)));
            let Some(bar) = weak.upgrade() else { return };
            if bar.is_finished() {
                return;
            }
            let elapsed = started.elapsed();
            if elapsed < next {
                continue;
            }
            next += every;
            let (pos, len) = (bar.position(), bar.length().unwrap_or(0));
            // Under 1% done the extrapolation says nothing (a tiny first
            // level finished, the large one running): no time left then.
            let left = if pos > 0 && len > pos && pos as f64 >= 0.01 * len as f64 {
                format!(
                    ", about {} left",
                    duration_words(elapsed.mul_f64((len - pos) as f64 / pos as f64))
                )
            } else {
                String::new()
            };
            match shown {
                Shown::Steps => eprintln!(
                    "varspec: {what}: {pos} of {len} after {}{left}",
                    duration_words(elapsed)
                ),
                Shown::Percent => eprintln!(
                    "varspec: {what}: {:.0}% done after {}{left}",
                    100.0 * pos as f64 / len.max(1) as f64,
                    duration_words(elapsed)
                ),
                Shown::Elapsed => eprintln!(
                    "varspec: {}: running for {}",
                    bar.message(),
                    duration_words(elapsed)
                ),
            }
        }
    });
}

/// "5.5 days", "2 h 05 min", "3 min 20 s", "45 s".
pub fn duration_words(d: Duration) -> String {
    let s = d.as_secs();
    if s >= 48 * 3600 {
        format!("{:.1} days", s as f64 / 86400.0)
    } else if s >= 3600 {
        format!("{} h {:02} min", s / 3600, s % 3600 / 60)
    } else if s >= 60 {
        format!("{} min {:02} s", s / 60, s % 60)
    } else {
        format!("{s} s")
    }
}

/// Estimated seconds of work above which a command says so before it
/// starts.
const LONG_WORK: f64 = 60.0;

/// Pair evaluations per second below any measured rate of the spatial
/// form (1.7e7 on the default disk, 4e7 on lighter integrands, on 2
/// cores): work under [`LONG_WORK`] times this cannot take a minute, and
/// is not timed.
const SLOWEST_PAIRS_PER_SECOND: f64 = 1e6;

/// Before the spatial form runs on `runs` (N, sets): a note when it would
/// take over a minute here, with the pair evaluations and the time
/// ([`varspec::variance::estimated_seconds`], one probe for all runs),
/// since its cost is O(N²) per set and nothing else warns of a run that
/// takes days. Work too small to matter is not probed.
pub fn note_spatial_cost(f: &dyn varspec::integrands::Integrand, runs: &[(usize, usize)]) {
    let pairs: f64 = runs
        .iter()
        .map(|&(n, sets)| sets as f64 * varspec::variance::pair_evaluations(f, n))
        .sum();
    if pairs < LONG_WORK * SLOWEST_PAIRS_PER_SECOND {
        return;
    }
    let Ok(seconds) = varspec::variance::estimated_seconds(f, runs) else {
        return;
    };
    if seconds > LONG_WORK {
        eprintln!(
            "note: the spatial form is O(N^2) per set: {pairs:.1e} pair evaluations, about {} \
             here; the fourier (or expected) form costs O(N log N)",
            duration_words(Duration::from_secs_f64(seconds))
        );
    }
}
