//! The FMI 3.0 calls of a well-behaved importer, as `planner` plans them for either version (the
//! same plans and value generators): initialisation with values in range, steps of 0.1 to 10 ms
//! or, for Model Exchange, an integrator's calls, gets, FMU states, termination, reset; mostly
//! with the rigid boom (`boom.flexible` = false); the probe paths of `probes`, derivatives in
//! Initialization Mode, and a smaller step retried after fmi3Discard; for a model with a Clock,
//! the calls of a clock master (`clock_master`). Here: its ops (`Planned`) and its own plans
//! (`Phases`).

use crate::clock_master;
use crate::model_description::{Description, Type};
use crate::ops::{Arr, Text};
use crate::ops3::Op3;
use crate::planner::{plausible_derivative, plausible_experiment, plausible_values, some_reals, state_op};
use crate::planner::{Phases, Planned, Planner};
use crate::probes::Probe;
use crate::rng::Rng;
use crate::session3::Session3;
use crate::fmu_states::StateCall;
use crate::view::View;

impl Phases<Session3<'_>, Op3> for Planner<Op3> {
    /// Gets, a restored FMU state, a reset, the end.
    fn step_failed(&mut self, rng: &mut Rng, s: &Session3) -> Op3 {
        match rng.below(10) {
            0..=3 => Op3::get_reals(rng, s.model),
            4 => restore(rng, s).unwrap_or(Op3::Reset),
            5..=7 => Op3::Reset,
            _ => Op3::Terminate,
        }
    }

    /// Now and then a restored FMU state, else a reset.
    fn unknown(&mut self, rng: &mut Rng, s: &Session3) -> Op3 {
        restore(rng, s).filter(|_| rng.chance(0.5)).unwrap_or(Op3::Reset)
    }

    /// In Step Mode: mostly steps, input changes and gets, some FMU state handling; once the
    /// budget or the stop time is reached, gets and the end of the simulation.
    fn stepping(&mut self, rng: &mut Rng, s: &Session3) -> Op3 {
        let m = s.model;
        if m.clock.is_some() {
            return clock_master::stepping(self, rng, s);
        }
        let room = s.view.room(s.budget());
        if let Some(h) = s.discarded.filter(|_| room >= 1e-6) {
            // FMI 3.0 4.2.1: after fmi3Discard, a smaller step from the same time.
            return Op3::DoStep { t: s.view.time, h: (h * rng.uniform(0.1, 0.5)).min(room), no_set_prior: true, null_outputs: false };
        }
        let h = match self.step_size(rng, m, room) {
            Ok(h) => h,
            Err(op) => return op,
        };
        match rng.below(100) {
            0..=44 => Op3::DoStep { t: s.view.time, h, no_set_prior: rng.chance(0.9), null_outputs: false },
            45..=62 => Op3::set(rng, m, &m.step_settable).unwrap_or_else(|| Op3::get_reals(rng, m)),
            63..=80 => Op3::get_reals(rng, m),
            81..=84 => {
                let ty = *rng.pick(&[Type::Integer, Type::Boolean, Type::String, Type::Enumeration]);
                get_all(m, ty)
            }
            85..=89 => state_op(rng, s),
            90 => self.start_round_trip(rng, s),
            91..=94 => self.spool(rng, s, h).unwrap_or_else(|| Op3::get_reals(rng, m)),
            _ => Op3::derivative(rng, m, false),
        }
    }

    /// Model Exchange in Continuous-Time Mode: the integrator's calls (`Planner::integrator`),
    /// gets, an event now and then, FMU states, nominals, the numbers of states and event indicators, derivatives.
    fn integrating(&mut self, rng: &mut Rng, s: &Session3) -> Op3 {
        let m = s.model;
        if m.clock.is_some() {
            return clock_master::integrating(self, rng, s);
        }
        match self.integrator(rng, s) {
            Ok(op) => op,
            Err(78..=84) => Op3::get_reals(rng, m),
            Err(85..=87) => Op3::EnterEventMode,
            Err(88..=92) => state_op(rng, s),
            Err(93) => Op3::GetNominalsOfContinuousStates { n: m.states, null: false },
            Err(94) => Op3::GetNumberOfContinuousStates { null: false },
            Err(95) => Op3::GetNumberOfEventIndicators { null: false },
            Err(96..=97) => Op3::derivative(rng, m, false),
            Err(_) => Op3::GetContinuousStates { n: m.states, null: false },
        }
    }

    /// With a Clock, the clock master's; else the shared plan.
    fn event_mode(&mut self, rng: &mut Rng, s: &Session3) -> Option<Op3> {
        s.model.clock.is_some().then(|| clock_master::event_mode(self, rng, s))
    }
}

/// fmi3SetFMUState of a live FMU state, if there is one.
fn restore(rng: &mut Rng, s: &Session3) -> Option<Op3> {
    rng.choose(&s.states.live).map(|l| Op3::State(StateCall::Set { state: l.ptr }))
}

/// FMI 3.0's ops as the planner makes them.
impl Planned for Op3 {
    const RESET: Op3 = Op3::Reset;
    const TERMINATE: Op3 = Op3::Terminate;
    const EXIT_INITIALIZATION_MODE: Op3 = Op3::ExitInitializationMode;
    const ENTER_CONTINUOUS_TIME_MODE: Op3 = Op3::EnterContinuousTimeMode;
    const UPDATE_DISCRETE_STATES: Op3 = Op3::UpdateDiscreteStates { null_flags: false };

    fn get_derivatives(m: &Description) -> Op3 {
        Op3::GetContinuousStateDerivatives { n: m.states, null: false }
    }

    fn completed_integrator_step(no_set_prior: bool) -> Op3 {
        Op3::CompletedIntegratorStep { no_set_prior, null_flags: false }
    }

    fn probe(p: Probe, m: &Description) -> Op3 {
        match p {
            Probe::Read(vr) => Op3::GetFloat64 { n_values: vr.len(), vr: Arr::Items(vr), null_values: false },
            Probe::Set(vr, values) => Op3::SetFloat64 { vr: Arr::Items(vr), values: Arr::Items(values) },
            Probe::DoStep { t, h } => Op3::DoStep { t, h, no_set_prior: true, null_outputs: false },
            Probe::GetContinuousStates => Op3::GetContinuousStates { n: m.states, null: false },
            Probe::GetEventIndicators => Op3::GetEventIndicators { n: m.event_indicators, null: false },
            Probe::SetTime(t) => Op3::SetTime { t },
            Probe::SetContinuousStates(x) => Op3::SetContinuousStates { x: Arr::Items(x) },
        }
    }

    /// fmi3Set<type> (fmi3SetInt64 for Enumerations).
    fn set(rng: &mut Rng, m: &Description, candidates: &[usize]) -> Option<Op3> {
        let (ty, vr, values) = plausible_values(rng, m, candidates)?;
        let vr = Arr::Items(vr);
        let bytes = |values: Vec<f64>| values.iter().map(|&x| u8::from(x != 0.0)).collect();
        Some(match ty {
            Type::Real => Op3::SetFloat64 { vr, values: Arr::Items(values) },
            Type::Integer => Op3::SetInt32 { vr, values: Arr::Items(values.iter().map(|&x| x as i32).collect()) },
            Type::Enumeration => Op3::SetInt64 { vr, values: Arr::Items(values.iter().map(|&x| x as i64).collect()) },
            Type::Boolean => Op3::SetBoolean { vr, values: Arr::Items(bytes(values)) },
            Type::String => {
                Op3::SetString { vr, values: Arr::Items(values.iter().map(|_| Text::new("fuzz")).collect()) }
            }
        })
    }

    /// fmi3GetFloat64.
    fn get_reals(rng: &mut Rng, m: &Description) -> Op3 {
        let vr = some_reals(rng, m);
        Op3::GetFloat64 { n_values: vr.len(), vr: Arr::Items(vr), null_values: false }
    }

    /// A directional (or, where provided, adjoint) derivative.
    fn derivative(rng: &mut Rng, m: &Description, initialization: bool) -> Op3 {
        let (unknowns, knowns, seeds) = plausible_derivative(rng, m, initialization);
        let adjoint = m.adjoint && rng.chance(0.3);
        // The adjoint's seeds weight the unknowns and its sensitivities are per known.
        let (seed, n_sensitivity) = if adjoint {
            (unknowns.iter().map(|_| rng.uniform(-1.0, 1.0)).collect(), knowns.len())
        } else {
            (seeds, unknowns.len())
        };
        Op3::Derivative {
            adjoint,
            unknowns: Arr::Items(unknowns),
            knowns: Arr::Items(knowns),
            seed: Arr::Items(seed),
            n_sensitivity,
            null_sensitivity: false,
        }
    }

    fn debug_logging(logging_on: bool, categories: Vec<Text>) -> Op3 {
        Op3::SetDebugLogging { logging_on, categories: Arr::Items(categories) }
    }

    fn rigid(vr: u32) -> Op3 {
        Op3::SetBoolean { vr: Arr::Items(vec![vr]), values: Arr::Items(vec![0]) }
    }

    /// None: FMI 3.0 passes the experiment to fmi3EnterInitializationMode.
    fn setup(_: &mut Rng, _: &View) -> Option<Op3> {
        None
    }

    fn enter_initialization_mode(rng: &mut Rng) -> Op3 {
        Op3::EnterInitializationMode(plausible_experiment(rng))
    }

    fn initialization_getters(_: &mut Rng, _: &Description) -> Vec<Op3> {
        Vec::new()
    }
}

/// The getter of type `ty` for every variable of that type.
fn get_all(m: &Description, ty: Type) -> Op3 {
    let vr = m.of_type(ty).to_vec();
    let n_values = vr.len();
    let vr = Arr::Items(vr);
    match ty {
        Type::Integer => Op3::GetInt32 { vr, n_values, null_values: false },
        Type::Enumeration => Op3::GetInt64 { vr, n_values, null_values: false },
        Type::Boolean => Op3::GetBoolean { vr, n_values, null_values: false },
        Type::String => Op3::GetString { vr, n_values, null_values: false },
        Type::Real => Op3::GetFloat64 { vr, n_values, null_values: false },
    }
}
