//! The FMI 3.0 calls of a well-behaved importer, as `planner` makes FMI 2.0's (the same plans
//! and value generators): initialisation with values in range, steps of 0.1 to 10 ms or, for
//! Model Exchange, an integrator's calls, gets, FMU states, termination, reset; mostly with the
//! rigid boom (`boom.flexible` = false); the probe paths of `probes`, derivatives in
//! Initialization Mode, and a smaller step retried after fmi3Discard.

use crate::model_description::{Description, Type};
use crate::ops::{Arr, Text};
use crate::ops3::Op3;
use crate::planner::{plausible_derivative, plausible_experiment, plausible_values, some_reals, state_call};
use crate::probes::{self, Probe, RoundTrip};
use crate::rng::Rng;
use crate::session3::Session3;
use crate::fmu_states::StateCall;
use crate::view::Phase;
use std::collections::VecDeque;

/// Proposes the next legal call from where the instance is.
pub struct Planner3 {
    /// Calls planned ahead, each for the phase it is legal in (dropped when the phase changes).
    queue: VecDeque<(Phase, Op3)>,
    /// The sequence's usual communication (or integration) step size.
    h: f64,
    /// Set once initialisation failed or the instance broke: plans keep the start values.
    tame: bool,
    round_trip: RoundTrip,
    /// A state-by-reference probe waits for the states just read.
    by_reference: bool,
}

impl Planner3 {
    pub fn new(rng: &mut Rng) -> Self {
        Planner3 { queue: VecDeque::new(), h: rng.log_uniform(1e-4, 1e-2), tame: false, round_trip: RoundTrip::default(), by_reference: false }
    }

    pub fn next(&mut self, rng: &mut Rng, s: &Session3) -> Op3 {
        if self.queue.front().is_some_and(|(phase, _)| *phase == s.view.phase) {
            return self.queue.pop_front().expect("a planned call").1;
        }
        self.queue.clear();
        if let Some(call) = self.round_trip.next(&s.states) {
            return Op3::State(call);
        }
        let m = s.model;
        let restore = |rng: &mut Rng| rng.choose(&s.states.live).map(|l| Op3::State(StateCall::Set { state: l.ptr }));
        match s.view.phase {
            Phase::Instantiated | Phase::Initialization => {
                self.plan_initialization(rng, s);
                self.queue.pop_front().map_or(Op3::Reset, |(_, op)| op)
            }
            Phase::StepComplete => self.stepping(rng, s),
            Phase::EventMode => match rng.below(12) {
                0..=5 => Op3::EnterContinuousTimeMode,
                6 => Op3::UpdateDiscreteStates { null_flags: false },
                7 => set(rng, m, &m.step_settable).unwrap_or(Op3::EnterContinuousTimeMode),
                8 => get_float64(rng, m),
                9 => Op3::GetContinuousStates { n: m.states, null: false },
                10 => Op3::State(state_call(rng, &s.states)),
                _ => Op3::Terminate,
            },
            Phase::ContinuousTime => self.integrating(rng, s),
            Phase::StepFailed => match rng.below(10) {
                0..=3 => get_float64(rng, m),
                4 => restore(rng).unwrap_or(Op3::Reset),
                5..=7 => Op3::Reset,
                _ => Op3::Terminate,
            },
            Phase::Terminated => match rng.below(4) {
                0 => get_float64(rng, m),
                1 => Op3::State(state_call(rng, &s.states)),
                _ => Op3::Reset,
            },
            Phase::Unknown => restore(rng).filter(|_| rng.chance(0.5)).unwrap_or(Op3::Reset),
            Phase::Broken => {
                self.tame = true;
                Op3::Reset
            }
        }
    }

    /// Queues start values, fmi3EnterInitializationMode with the experiment, more values and
    /// fmi3ExitInitializationMode (from where the instance is).
    fn plan_initialization(&mut self, rng: &mut Rng, s: &Session3) {
        let m = s.model;
        let tame = self.tame;
        let sets = |rng: &mut Rng| if tame { 0 } else { rng.below(3) };
        let mut plan = |phase: Phase, op: Option<Op3>| self.queue.extend(op.map(|op| (phase, op)));
        if s.view.phase == Phase::Instantiated {
            if rng.chance(0.2) {
                let categories =
                    (0..rng.below(3)).filter_map(|_| rng.choose(&m.categories)).map(|c| Text::new(c)).collect();
                let logging_on = rng.chance(0.5);
                plan(Phase::Instantiated, Some(Op3::SetDebugLogging { logging_on, categories: Arr::Items(categories) }));
            }
            if let Some(vr) = m.flexible.filter(|_| rng.chance(0.85)) {
                plan(Phase::Instantiated, Some(Op3::SetBoolean { vr: Arr::Items(vec![vr]), values: Arr::Items(vec![0]) }));
            }
            for _ in 0..sets(rng) {
                plan(Phase::Instantiated, set(rng, m, &m.init_settable));
            }
            plan(Phase::Instantiated, Some(Op3::EnterInitializationMode(plausible_experiment(rng))));
        }
        for _ in 0..sets(rng) {
            plan(Phase::Initialization, set(rng, m, &m.init_settable));
        }
        if rng.chance(0.2) {
            plan(Phase::Initialization, Some(get_float64(rng, m)));
        }
        if rng.chance(0.2) {
            plan(Phase::Initialization, Some(derivative(rng, m, true)));
        }
        plan(Phase::Initialization, Some(Op3::ExitInitializationMode));
    }

    /// Queues a probe's calls for `phase` and returns the first (`None` for an empty probe).
    fn probe(&mut self, phase: Phase, probe: Vec<Probe>, m: &Description) -> Option<Op3> {
        self.queue.extend(probe.into_iter().map(|p| (phase, probe_op(p, m))));
        self.queue.pop_front().map(|(_, op)| op)
    }

    /// In Step Mode: mostly steps, input changes and gets, some FMU state handling; once the
    /// budget or the stop time is reached, gets and the end of the simulation.
    fn stepping(&mut self, rng: &mut Rng, s: &Session3) -> Op3 {
        let m = s.model;
        let room = s.view.room(s.budget());
        if let Some(h) = s.discarded.filter(|_| room >= 1e-6) {
            // FMI 3.0 4.2.1: after fmi3Discard, a smaller step from the same time.
            return Op3::DoStep { t: s.view.time, h: (h * rng.uniform(0.1, 0.5)).min(room), no_set_prior: true, null_outputs: false };
        }
        if room < 1e-6 {
            return match rng.below(10) {
                0..=5 => get_float64(rng, m),
                6..=8 => Op3::Terminate,
                _ => Op3::Reset,
            };
        }
        let h = if rng.chance(0.8) { self.h } else { rng.log_uniform(1e-4, 1e-2) };
        match rng.below(100) {
            0..=44 => Op3::DoStep { t: s.view.time, h: h.min(room), no_set_prior: rng.chance(0.9), null_outputs: false },
            45..=62 => set(rng, m, &m.step_settable).unwrap_or_else(|| get_float64(rng, m)),
            63..=80 => get_float64(rng, m),
            81..=84 => {
                let ty = *rng.pick(&[Type::Integer, Type::Boolean, Type::String]);
                get_all(m, ty)
            }
            85..=89 => Op3::State(state_call(rng, &s.states)),
            90 => {
                self.round_trip.start();
                Op3::State(state_call(rng, &s.states))
            }
            91..=94 => {
                let probe = probes::spool(rng, m, &s.view, h.min(room));
                self.probe(Phase::StepComplete, probe, m).unwrap_or_else(|| get_float64(rng, m))
            }
            _ => derivative(rng, m, false),
        }
    }

    /// Model Exchange in Continuous-Time Mode, as an integrator drives it: time forward by up to
    /// the sequence's step, states near the last ones read, derivatives, event indicators,
    /// completed steps, continuous inputs, an event now and then; terminated after 1 s.
    fn integrating(&mut self, rng: &mut Rng, s: &Session3) -> Op3 {
        let m = s.model;
        if !(s.view.time < 1.0) {
            return if rng.chance(0.7) { Op3::Terminate } else { Op3::Reset };
        }
        let probe = probes::integrating(
            rng,
            m,
            (&s.x, s.x_fresh),
            (&s.view, self.h),
            &mut self.by_reference,
            &mut self.round_trip,
        );
        if let Some(op) = self.probe(Phase::ContinuousTime, probe, m) {
            return op;
        }
        match rng.below(100) {
            0..=19 => Op3::SetTime { t: s.view.time + self.h * rng.uniform(0.0, 1.0) },
            20..=34 if s.x.len() == m.states => {
                let x = s.x.iter().map(|x| x + (1e-6 + 1e-4 * x.abs()) * rng.uniform(-1.0, 1.0)).collect();
                Op3::SetContinuousStates { x: Arr::Items(x) }
            }
            20..=34 => Op3::GetContinuousStates { n: m.states, null: false },
            35..=59 => Op3::GetContinuousStateDerivatives { n: m.states, null: false },
            60..=64 => Op3::GetEventIndicators { n: m.event_indicators, null: false },
            65..=69 => Op3::CompletedIntegratorStep { no_set_prior: rng.chance(0.9), null_flags: false },
            70..=77 => set(rng, m, &m.real_inputs).unwrap_or_else(|| get_float64(rng, m)),
            78..=84 => get_float64(rng, m),
            85..=87 => Op3::EnterEventMode,
            88..=92 => Op3::State(state_call(rng, &s.states)),
            93 => Op3::GetNominalsOfContinuousStates { n: m.states, null: false },
            94 => Op3::GetNumberOfContinuousStates { null: false },
            95 => Op3::GetNumberOfEventIndicators { null: false },
            96..=97 => derivative(rng, m, false),
            _ => Op3::GetContinuousStates { n: m.states, null: false },
        }
    }
}

/// fmi3Set<type> of one to three variables from `candidates` with values in range.
fn set(rng: &mut Rng, m: &Description, candidates: &[usize]) -> Option<Op3> {
    let (ty, vr, values) = plausible_values(rng, m, candidates)?;
    let vr = Arr::Items(vr);
    Some(match ty {
        Type::Real => Op3::SetFloat64 { vr, values: Arr::Items(values) },
        Type::Integer => Op3::SetInt32 { vr, values: Arr::Items(values.iter().map(|&x| x as i32).collect()) },
        Type::Boolean => Op3::SetBoolean { vr, values: Arr::Items(values.iter().map(|&x| u8::from(x != 0.0)).collect()) },
        Type::String => Op3::SetString { vr, values: Arr::Items(values.iter().map(|_| Text::new("fuzz")).collect()) },
    })
}

/// fmi3GetFloat64 of the outputs, of a few Float64s, or of every one.
fn get_float64(rng: &mut Rng, m: &Description) -> Op3 {
    let vr = some_reals(rng, m);
    Op3::GetFloat64 { n_values: vr.len(), vr: Arr::Items(vr), null_values: false }
}

/// The getter of type `ty` for every variable of that type.
fn get_all(m: &Description, ty: Type) -> Op3 {
    let vr = m.of_type(ty).to_vec();
    let n_values = vr.len();
    let vr = Arr::Items(vr);
    match ty {
        Type::Integer => Op3::GetInt32 { vr, n_values, null_values: false },
        Type::Boolean => Op3::GetBoolean { vr, n_values, null_values: false },
        Type::String => Op3::GetString { vr, n_values, null_values: false },
        Type::Real => Op3::GetFloat64 { vr, n_values, null_values: false },
    }
}

/// A probe's call as an FMI 3.0 op.
fn probe_op(p: Probe, m: &Description) -> Op3 {
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

/// A directional (or, where provided, adjoint) derivative as `plausible_derivative` draws it
/// (`initialization`: for Initialization Mode).
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
