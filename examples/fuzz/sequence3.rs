//! An FMI 3.0 sequence: one fmi3InstantiateCoSimulation or fmi3InstantiateModelExchange (mostly
//! valid), 20 to 200 calls, mostly planned (`planner3`), some wild (`wild3`), and
//! fmi3FreeInstance; run by `sequence` like FMI 2.0's.

use crate::fmi3::Library;
use crate::ops3::Op3;
use crate::planner3::Planner3;
use crate::report::{Report, Subject};
use crate::rng::Rng;
use crate::sequence::{run_logged, CALLS, CALLS_WITHOUT_INSTANCE};
use crate::session::Target;
use crate::session3::Session3;
use crate::wild3::{instantiation3, wild3};
use std::path::Path;

impl Subject for Library {
    fn identifier(&self) -> &str {
        &self.model.identifier
    }
    fn path(&self) -> &Path {
        &self.path
    }
    fn fmi(&self) -> u8 {
        3
    }
    fn run_sequence(&self, seed: u64, report: &mut Report) -> Result<(), String> {
        run_logged(true, seed, report, |report| drive(&mut Session3::new(self, report), seed))
    }
}

/// The calls: instantiation, a mix of planned and wild calls (all wild without an instance, a
/// few on a NULL instance), the frees.
fn drive(s: &mut Session3, seed: u64) -> Result<(), String> {
    let mut rng = Rng::new(seed);
    s.call(Op3::Instantiate(instantiation3(&mut rng, s.model)), Target::Main)?;
    let wildness = *rng.pick(&[0.02, 0.02, 0.05, 0.1, 0.3, 1.0]);
    let mut calls = rng.range(CALLS.0, CALLS.1);
    if s.c.is_null() {
        calls = calls.min(CALLS_WITHOUT_INSTANCE);
    }
    let mut planner = Planner3::new(&mut rng);
    for _ in 0..calls {
        let op = if s.c.is_null() || rng.chance(wildness) { wild3(&mut rng, s) } else { planner.next(&mut rng, s) };
        let null = op.takes_instance() && (s.c.is_null() || rng.chance(0.01));
        s.call(op, if null { Target::Null } else { Target::Main })?;
    }
    let (second, main) = (s.second, s.c);
    if !second.is_null() {
        s.call(Op3::FreeInstance { instance: second }, Target::Main)?;
    }
    s.call(Op3::FreeInstance { instance: main }, Target::Main)
}
