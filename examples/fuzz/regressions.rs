//! The regressions: every failing sequence the fuzzer has found, listed in `LIST` one a line as
//! `<ModelIdentifier> <sequence seed>  # what it found` (the seed's top bit is its FMI version,
//! `rng::seed_version`), and replayed by `--regressions FILE` in forked children like the other
//! sequences, on the library of that identifier through that version.

use crate::batch::{fuzz_library, Sequences};
use crate::report::{Subject, Tally};
use crate::rng::seed_version;
use std::path::Path;

/// The committed list, from the repository's root.
pub const LIST: &str = "examples/fuzz/regressions.txt";

/// One listed sequence.
struct Regression {
    identifier: String,
    seed: u64,
}

/// The sequences listed in `path`: `#` starts a comment, blank lines are skipped.
fn read(path: &Path) -> Result<Vec<Regression>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut list = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or_default();
        let fields: Vec<&str> = line.split_whitespace().collect();
        match fields[..] {
            [] => {}
            [identifier, seed] => {
                let seed =
                    seed.parse().map_err(|_| format!("{}:{}: {seed:?} is no sequence seed", path.display(), n + 1))?;
                list.push(Regression { identifier: identifier.to_owned(), seed });
            }
            _ => {
                return Err(format!("{}:{}: not `<ModelIdentifier> <sequence seed>  # comment`", path.display(), n + 1))
            }
        }
    }
    Ok(list)
}

/// Replays the sequences listed in `path` on those of `subjects` with their identifier and FMI
/// version: their tally, and how many were skipped (no such library and version in the run).
pub fn replay(path: &Path, subjects: &[Box<dyn Subject>]) -> Result<(Tally, usize), String> {
    let list = read(path)?;
    let mut tally = Tally::default();
    let mut replayed = 0;
    for subject in subjects {
        let seeds: Vec<u64> = list
            .iter()
            .filter(|r| r.identifier == subject.identifier() && seed_version(r.seed) == subject.fmi())
            .map(|r| r.seed)
            .collect();
        if seeds.is_empty() {
            continue;
        }
        replayed += seeds.len();
        let t = fuzz_library(subject.as_ref(), &Sequences::Listed(&seeds))?;
        if tally.first_internal_error.is_none() {
            tally.first_internal_error = t.first_internal_error.clone();
        }
        tally.add_timed(&t);
    }
    Ok((tally, list.len() - replayed))
}
