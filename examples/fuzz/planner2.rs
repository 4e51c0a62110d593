//! The FMI 2.0 calls of a well-behaved importer, as `planner` plans them for either version:
//! its ops (`Planned`), its plans between steps, while integrating, after a failed step or where
//! the phase is unknown (`Phases`), input derivatives and, in Co-Simulation, a step that clamps
//! an interpolated input at its bound followed by an FMU state round trip.

use crate::fmi2::{LAST_SUCCESSFUL_TIME, TERMINATED};
use crate::fmu_states::StateCall;
use crate::model_description::{Description, Type, Variable};
use crate::ops::{Arr, Op, Text};
use crate::planner::{
    plausible_derivative, plausible_experiment, plausible_values, some_reals, state_op, Phases, Planned, Planner,
};
use crate::probes::Probe;
use crate::rng::Rng;
use crate::session::Session;
use crate::view::{Phase, View};
use std::os::raw::c_int;

/// fmi2GetRealStatus(fmi2LastSuccessfulTime).
const LAST_SUCCESSFUL_TIME_STATUS: Op = Op::GetRealStatus { kind: LAST_SUCCESSFUL_TIME, null_value: false };

impl Planner<Op> {
    /// Co-Simulation: an input near a bound, a slope that drives it across within the step, the
    /// step (where the FMU clamps the interpolated input), then an FMU state round trip.
    fn clamp(&mut self, rng: &mut Rng, s: &Session, h: f64) -> Option<Op> {
        let m = s.model;
        let v = &m.variables[*rng.choose(&m.real_inputs)?];
        if !(v.min.is_finite() && v.max.is_finite() && v.max > v.min) {
            return None;
        }
        let (span, up) = (v.max - v.min, rng.chance(0.5));
        let (start, slope) = if up { (v.max - 0.02 * span, span / h) } else { (v.min + 0.02 * span, -span / h) };
        let slope = slope * rng.uniform(0.5, 5.0);
        let vr = Arr::Items(vec![v.vr]);
        let set = Op::SetReal { vr: vr.clone(), values: Arr::Items(vec![start]) };
        let slopes = Op::SetRealInputDerivatives { vr, orders: Arr::Items(vec![1]), values: Arr::Items(vec![slope]) };
        let step = Op::DoStep { t: s.view.time, h, no_set_prior: 1 };
        self.plan_with_round_trip(Phase::StepComplete, vec![set, slopes, step])
    }
}

impl Phases<Session<'_>, Op> for Planner<Op> {
    /// Between steps: mostly steps, input changes and gets, some FMU state handling; once the
    /// budget or the stop time is reached, gets and the end of the simulation.
    fn stepping(&mut self, rng: &mut Rng, s: &Session) -> Op {
        let m = s.model;
        let h = match self.step_size(rng, m, s.view.room(s.budget())) {
            Ok(h) => h,
            Err(op) => return op,
        };
        match rng.below(100) {
            0..=44 => Op::DoStep { t: s.view.time, h, no_set_prior: c_int::from(rng.chance(0.9)) },
            45..=59 => Op::set(rng, m, &m.step_settable).unwrap_or_else(|| Op::get_reals(rng, m)),
            60..=64 => plausible_slopes(rng, m).unwrap_or_else(|| Op::get_reals(rng, m)),
            65..=82 => Op::get_reals(rng, m),
            83..=84 if rng.chance(0.5) => {
                Op::GetInteger { vr: Arr::Items(m.of_type(Type::Integer).to_vec()), null_values: false }
            }
            83..=84 => Op::GetBoolean { vr: Arr::Items(m.of_type(Type::Boolean).to_vec()), null_values: false },
            85..=88 => state_op(rng, s),
            89 => self.start_round_trip(rng, s),
            90..=91 => self.clamp(rng, s, h).unwrap_or_else(|| Op::get_reals(rng, m)),
            92..=94 => self.spool(rng, s, h).unwrap_or_else(|| state_op(rng, s)),
            95..=96 => state_op(rng, s),
            97 => Op::derivative(rng, m, false),
            98 => LAST_SUCCESSFUL_TIME_STATUS,
            _ => Op::GetBooleanStatus { kind: TERMINATED, null_value: false },
        }
    }

    /// Model Exchange in Continuous-Time Mode: the integrator's calls (`Planner::integrator`),
    /// gets, an event now and then, FMU states, nominals, a derivative.
    fn integrating(&mut self, rng: &mut Rng, s: &Session) -> Op {
        let m = s.model;
        match self.integrator(rng, s) {
            Ok(op) => op,
            Err(78..=86) => Op::get_reals(rng, m),
            Err(87..=89) => Op::EnterEventMode,
            Err(90..=94) => state_op(rng, s),
            Err(95..=96) => Op::GetNominalsOfContinuousStates { n: m.states, null: false },
            Err(97) => Op::derivative(rng, m, false),
            Err(_) => Op::GetContinuousStates { n: m.states, null: false },
        }
    }

    /// fmi2GetRealStatus(fmi2LastSuccessfulTime), whether it terminated, gets, a restore, the end.
    fn step_failed(&mut self, rng: &mut Rng, s: &Session) -> Op {
        match rng.below(10) {
            0..=2 => LAST_SUCCESSFUL_TIME_STATUS,
            3 => Op::GetBooleanStatus { kind: TERMINATED, null_value: false },
            4..=5 => Op::get_reals(rng, s.model),
            6 if !s.states.live.is_empty() => Op::State(StateCall::Set { state: rng.pick(&s.states.live).ptr }),
            6..=8 => Op::Reset,
            _ => Op::Terminate,
        }
    }

    /// fmi2GetRealStatus(fmi2LastSuccessfulTime), which tells whether a step was done.
    fn unknown(&mut self, _: &mut Rng, _: &Session) -> Op {
        LAST_SUCCESSFUL_TIME_STATUS
    }
}

/// FMI 2.0's ops as the planner makes them.
impl Planned for Op {
    const RESET: Op = Op::Reset;
    const TERMINATE: Op = Op::Terminate;
    const EXIT_INITIALIZATION_MODE: Op = Op::ExitInitializationMode;
    const ENTER_CONTINUOUS_TIME_MODE: Op = Op::EnterContinuousTimeMode;
    const UPDATE_DISCRETE_STATES: Op = Op::NewDiscreteStates { null_info: false };

    fn get_derivatives(m: &Description) -> Op {
        Op::GetDerivatives { n: m.states, null: false }
    }

    fn completed_integrator_step(no_set_prior: bool) -> Op {
        Op::CompletedIntegratorStep { no_set_prior: c_int::from(no_set_prior), null_flags: false }
    }

    fn probe(p: Probe, m: &Description) -> Op {
        match p {
            Probe::Read(vr) => Op::GetReal { vr: Arr::Items(vr), null_values: false },
            Probe::Set(vr, values) => Op::SetReal { vr: Arr::Items(vr), values: Arr::Items(values) },
            Probe::DoStep { t, h } => Op::DoStep { t, h, no_set_prior: 1 },
            Probe::GetContinuousStates => Op::GetContinuousStates { n: m.states, null: false },
            Probe::GetEventIndicators => Op::GetEventIndicators { n: m.event_indicators, null: false },
            Probe::SetTime(t) => Op::SetTime { t },
            Probe::SetContinuousStates(x) => Op::SetContinuousStates { x: Arr::Items(x) },
        }
    }

    /// fmi2Set<type>.
    fn set(rng: &mut Rng, m: &Description, candidates: &[usize]) -> Option<Op> {
        let (ty, vr, values) = plausible_values(rng, m, candidates)?;
        let vr = Arr::Items(vr);
        let ints = |f: fn(f64) -> c_int| Arr::Items(values.iter().map(|&x| f(x)).collect());
        Some(match ty {
            Type::Real => Op::SetReal { vr, values: Arr::Items(values.clone()) },
            // FMI 2.0's Enumerations are Integers (`model_description`): no Enumeration here.
            Type::Integer | Type::Enumeration => Op::SetInteger { vr, values: ints(|x| x as c_int) },
            Type::Boolean => Op::SetBoolean { vr, values: ints(|x| c_int::from(x != 0.0)) },
            Type::String => {
                Op::SetString { vr, values: Arr::Items(values.iter().map(|_| Text::new("fuzz")).collect()) }
            }
        })
    }

    fn get_reals(rng: &mut Rng, m: &Description) -> Op {
        Op::GetReal { vr: Arr::Items(some_reals(rng, m)), null_values: false }
    }

    /// fmi2GetDirectionalDerivative.
    fn derivative(rng: &mut Rng, m: &Description, initialization: bool) -> Op {
        let (unknowns, knowns, dv_known) = plausible_derivative(rng, m, initialization);
        Op::GetDirectionalDerivative {
            unknowns: Arr::Items(unknowns),
            knowns: Arr::Items(knowns),
            dv_known: Arr::Items(dv_known),
            null_dv_unknown: false,
        }
    }

    fn debug_logging(logging_on: bool, categories: Vec<Text>) -> Op {
        Op::SetDebugLogging { logging_on: c_int::from(logging_on), categories: Arr::Items(categories) }
    }

    fn rigid(vr: u32) -> Op {
        Op::SetBoolean { vr: Arr::Items(vec![vr]), values: Arr::Items(vec![0]) }
    }

    /// fmi2SetupExperiment as an importer calls it (see `plausible_experiment`).
    fn setup(rng: &mut Rng, view: &View) -> Option<Op> {
        if view.set_up {
            return None;
        }
        let e = plausible_experiment(rng);
        Some(Op::SetupExperiment {
            tolerance_defined: c_int::from(e.tolerance_defined),
            tolerance: e.tolerance,
            start: e.start,
            stop_defined: c_int::from(e.stop_defined),
            stop: e.stop,
        })
    }

    fn enter_initialization_mode(_: &mut Rng) -> Op {
        Op::EnterInitializationMode
    }

    /// Now and then, the derivatives and the nominals of the states.
    fn initialization_getters(rng: &mut Rng, m: &Description) -> Vec<Op> {
        if !rng.chance(0.3) {
            return Vec::new();
        }
        vec![
            Op::GetDerivatives { n: m.states, null: false },
            Op::GetNominalsOfContinuousStates { n: m.states, null: false },
        ]
    }
}

/// First-order derivatives of one or two Real inputs, of a size that keeps them in range for a while.
fn plausible_slopes(rng: &mut Rng, m: &Description) -> Option<Op> {
    let vars: Vec<&Variable> =
        (0..rng.range(1, 2)).filter_map(|_| rng.choose(&m.real_inputs)).map(|&i| &m.variables[i]).collect();
    if vars.is_empty() {
        return None;
    }
    let values = vars
        .iter()
        .map(|v| {
            let (lo, hi) = v.span();
            (hi - lo) * rng.uniform(-0.5, 0.5)
        })
        .collect();
    Some(Op::SetRealInputDerivatives {
        vr: Arr::Items(vars.iter().map(|v| v.vr).collect()),
        orders: Arr::Items(vec![1; vars.len()]),
        values: Arr::Items(values),
    })
}
