//! The command line's wrong-argument paths: negative numbers reach the value checks (they used
//! to be taken for options), an operating point out of range names the value and the range, and
//! a benchmark of zero duration is refused instead of printing a table of zeros, a parameter
//! of `boomsim eigen --set` is checked as the FMU checks it, and `boomsim linearize` refuses a
//! point without a steady lowering and a file it cannot write.

use std::process::Command;

fn boomsim(args: &[&str]) -> (bool, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_boomsim")).args(args).output().expect("boomsim runs");
    (out.status.success(), String::from_utf8_lossy(&out.stderr).into_owned())
}

#[test]
fn wrong_arguments_get_one_clear_line() {
    let cases: [(&[&str], &[&str]); 21] = [
        (&["analyze", "--xc", "-10"], &["x_c = -10 mm is outside the stroke [0, 500] mm"]),
        (&["analyze", "--p4", "-5"], &["p4 = -5 bar must be >= 0"]),
        (&["bench", "--duration", "0"], &["0 is not a positive number of seconds"]),
        (
            &["pack", "--platforms", "darwin64", "--out", "target/cli-test"],
            &["unknown platform \"darwin64\"", "linux64, win64, aarch64-linux"],
        ),
        (&["eigen", "--set", "boom.n2=40"], &["boom.n2 = 40 is outside its valid range [0, 16]"]),
        (&["eigen", "--set", "boom.xi=-0.1"], &["boom.xi = -0.1 is outside its valid range [0, 1]"]),
        (&["eigen", "--set", "p3=1"], &["HydraulicBoom has no parameter \"p3\""]),
        (&["eigen", "--set", "boom.n2"], &["expected NAME=VALUE"]),
        (&["bench", "--set", "boom.damping=4"], &["boom.damping = 4 is no item of DampingLaw; valid: 0 (thesis), 1"]),
        (&["eigen", "--set", "boom.damping=viscous"], &["boom.damping = viscous is no item of DampingLaw", "3 (converged_modal)"]),
        (&["bench", "--set", "boom.damping=1", "--json"], &["does not go with --json"]),
        (&["bench", "--realtime", "--set", "boom.damping=1"], &["does not go with --realtime"]),
        (&["linearize", "--u-ref", "-2"], &["--u-ref -2 is outside [-1, 1]"]),
        (&["linearize", "--u-ref", "0"], &["valve.u_ref = 0: a steady lowering needs a reference below 0", "--rest"]),
        (&["linearize", "--stroke", "600"], &["start.x = 0.6 is outside the stroke [0, 0.5] m"]),
        (&["linearize", "--output", "p9"], &["--output p9: not an output of the HydraulicBoom", "p4"]),
        (&["linearize", "--at", "-1"], &["--at -1 s is outside (0, 1000] s"]),
        (&["linearize", "--out", "model.txt"], &["--out model.txt: the extension must be .json, .npz or .mat"]),
        (&["linearize", "--feedback", "--k-f", "1"], &["--k-f 1 is outside [0, 1e-8] m4.s2/kg (K_f)"]),
        (
            &["linearize", "--model", "HydraulicCircuit", "--rest"],
            &["HydraulicCircuit is linearised at a steady lowering"],
        ),
        (
            &["linearize", "--model", "HydraulicCircuit", "--feedback", "--sine", "1"],
            &["--sine drives the HydraulicBoom's closed loop"],
        ),
    ];
    for (args, expected) in cases {
        let (ok, e) = boomsim(args);
        assert!(!ok && expected.iter().all(|x| e.contains(x)), "{args:?}: {e}");
    }
}
