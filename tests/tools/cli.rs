//! The command line's wrong-argument paths: negative numbers reach the value checks (they used
//! to be taken for options), an operating point out of range names the value and the range, and
//! a benchmark of zero duration is refused instead of printing a table of zeros.

use std::process::Command;

fn boomsim(args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_boomsim")).args(args).output().expect("boomsim runs");
    (out.status.success(), String::from_utf8_lossy(&out.stderr).into_owned())
}

#[test]
fn wrong_arguments_get_one_clear_line() {
    let (ok, e) = boomsim(&["analyze", "--xc", "-10"]);
    assert!(!ok && e.contains("x_c = -10 mm is outside the stroke [0, 500] mm"), "{e}");
    let (ok, e) = boomsim(&["analyze", "--p4", "-5"]);
    assert!(!ok && e.contains("p4 = -5 bar must be >= 0"), "{e}");
    let (ok, e) = boomsim(&["bench", "--duration", "0"]);
    assert!(!ok && e.contains("0 is not a positive number of seconds"), "{e}");
    let (ok, e) = boomsim(&["pack", "--platforms", "darwin64", "--out", "target/cli-test"]);
    assert!(!ok && e.contains("unknown platform \"darwin64\"") && e.contains("linux64, win64, aarch64-linux"), "{e}");
}
