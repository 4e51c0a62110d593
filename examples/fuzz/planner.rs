//! The calls of a well-behaved importer, so that the models really simulate: setup,
//! initialisation with values in range, steps of 0.1 to 10 ms, gets, FMU states, termination,
//! reset; mostly with the rigid boom (`boom.flexible` = false); the probe paths of `probes`,
//! derivatives in Initialization Mode and, in Co-Simulation, a step that clamps an interpolated
//! input at its bound followed by an FMU state round trip. `Planner` plans them for either
//! version: its ops (`Planned`) and its own plans (`Phases`) are in `planner2` and `planner3`;
//! here are the plans and value generators the versions share.

use crate::bookkeeping::Bookkeeping;
use crate::fmu_states::{FmuStates, StateCall};
use crate::model_description::{Description, Type};
use crate::ops::{Slot, Text};
use crate::probes::{self, Probe, RoundTrip};
use crate::rng::Rng;
use crate::sequence::Call;
use crate::view::{Phase, View};
use crate::wild::blob;
use std::collections::VecDeque;
use std::ops::Deref;
use std::ptr::null_mut;

/// Proposes the next legal call from where the instance is, for either version (`O`, its ops).
pub struct Planner<O> {
    /// Calls planned ahead, each for the phase it is legal in (dropped when the phase changes).
    queue: VecDeque<(Phase, O)>,
    /// The sequence's usual communication (or integration) step size.
    h: f64,
    /// Set once initialisation failed or the instance broke: plans keep the parameters' start values.
    tame: bool,
    round_trip: RoundTrip,
    /// A state-by-reference probe waits for the states just read.
    by_reference: bool,
}

/// The plans of a version's own (`S`: its session, `O`: its ops).
pub trait Phases<S, O> {
    /// Between steps (Co-Simulation).
    fn stepping(&mut self, rng: &mut Rng, s: &S) -> O;
    /// In Continuous-Time Mode (Model Exchange).
    fn integrating(&mut self, rng: &mut Rng, s: &S) -> O;
    /// After a step that failed.
    fn step_failed(&mut self, rng: &mut Rng, s: &S) -> O;
    /// Where the fuzzer does not know the instance's phase.
    fn unknown(&mut self, rng: &mut Rng, s: &S) -> O;
    /// In Event Mode, where the version has a plan of its own (FMI 3.0 with a Clock); else the
    /// shared plan.
    fn event_mode(&mut self, _: &mut Rng, _: &S) -> Option<O> {
        None
    }
}

/// A version's ops as the planner makes them.
pub trait Planned: Call + Sized {
    const RESET: Self;
    const TERMINATE: Self;
    const EXIT_INITIALIZATION_MODE: Self;
    const ENTER_CONTINUOUS_TIME_MODE: Self;
    /// fmi2NewDiscreteStates, fmi3UpdateDiscreteStates.
    const UPDATE_DISCRETE_STATES: Self;
    /// fmi2GetDerivatives, fmi3GetContinuousStateDerivatives.
    fn get_derivatives(m: &Description) -> Self;
    fn completed_integrator_step(no_set_prior: bool) -> Self;
    /// A probe's call (or one like it).
    fn probe(p: Probe, m: &Description) -> Self;
    /// A set of one to three variables of one type from `candidates` (indices), values in range.
    fn set(rng: &mut Rng, m: &Description, candidates: &[usize]) -> Option<Self>;
    /// A get of the outputs, of a few Reals, or of every Real (`some_reals`).
    fn get_reals(rng: &mut Rng, m: &Description) -> Self;
    /// A derivative as `plausible_derivative` draws it (`initialization`: for Initialization Mode).
    fn derivative(rng: &mut Rng, m: &Description, initialization: bool) -> Self;
    fn debug_logging(logging_on: bool, categories: Vec<Text>) -> Self;
    /// `boom.flexible` (`vr`) set to false.
    fn rigid(vr: u32) -> Self;
    /// The experiment's setup before the start values, where the version has one and it is not done.
    fn setup(rng: &mut Rng, view: &View) -> Option<Self>;
    fn enter_initialization_mode(rng: &mut Rng) -> Self;
    /// The getters planned in Initialization Mode of a Model Exchange instance.
    fn initialization_getters(rng: &mut Rng, m: &Description) -> Vec<Self>;
}

impl<O: Planned> Planner<O> {
    pub fn new(rng: &mut Rng) -> Self {
        Planner {
            queue: VecDeque::new(),
            h: rng.log_uniform(1e-4, 1e-2),
            tame: false,
            round_trip: RoundTrip::default(),
            by_reference: false,
        }
    }

    /// The call planned for the instance's phase; else, the plan dropped, the round trip's next.
    fn queued(&mut self, s: &Bookkeeping) -> Option<O> {
        if self.queue.front().is_some_and(|(phase, _)| *phase == s.view.phase) {
            return self.queue.pop_front().map(|(_, op)| op);
        }
        self.queue.clear();
        self.round_trip.next(&s.states).map(O::state)
    }

    /// Instantiated or in Initialization Mode: the first call of the initialisation's plan.
    fn initialization(&mut self, rng: &mut Rng, s: &Bookkeeping) -> O {
        self.plan_initialization(rng, s);
        self.queue.pop_front().map_or(O::RESET, |(_, op)| op)
    }

    /// Queues setup (FMI 2.0), start values, EnterInitializationMode (FMI 3.0: with the
    /// experiment), more values and ExitInitializationMode (from where the instance is).
    /// `boom.flexible` is set to false in most sequences: the flexible boom is slow.
    fn plan_initialization(&mut self, rng: &mut Rng, s: &Bookkeeping) {
        let m = s.model;
        let tame = self.tame;
        let sets = |rng: &mut Rng| if tame { 0 } else { rng.below(3) };
        let mut plan = |phase: Phase, op: Option<O>| self.queue.extend(op.map(|op| (phase, op)));
        if s.view.phase == Phase::Instantiated {
            if rng.chance(0.2) {
                let categories =
                    (0..rng.below(3)).filter_map(|_| rng.choose(&m.categories)).map(|c| Text::new(c)).collect();
                let logging_on = rng.chance(0.5);
                plan(Phase::Instantiated, Some(O::debug_logging(logging_on, categories)));
            }
            plan(Phase::Instantiated, O::setup(rng, &s.view));
            if let Some(vr) = m.flexible.filter(|_| rng.chance(0.85)) {
                plan(Phase::Instantiated, Some(O::rigid(vr)));
            }
            for _ in 0..sets(rng) {
                plan(Phase::Instantiated, O::set(rng, m, &m.init_settable));
            }
            plan(Phase::Instantiated, Some(O::enter_initialization_mode(rng)));
        }
        for _ in 0..sets(rng) {
            plan(Phase::Initialization, O::set(rng, m, &m.init_settable));
        }
        if rng.chance(0.2) {
            plan(Phase::Initialization, Some(O::get_reals(rng, m)));
        }
        if rng.chance(0.2) {
            plan(Phase::Initialization, Some(O::derivative(rng, m, true)));
        }
        if s.me {
            for op in O::initialization_getters(rng, m) {
                plan(Phase::Initialization, Some(op));
            }
        }
        plan(Phase::Initialization, Some(O::EXIT_INITIALIZATION_MODE));
    }

    /// Queues a probe's calls for `phase` and returns the first (`None` for an empty probe).
    fn probe(&mut self, phase: Phase, probe: Vec<Probe>, m: &Description) -> Option<O> {
        self.queue.extend(probe.into_iter().map(|p| (phase, O::probe(p, m))));
        self.queue.pop_front().map(|(_, op)| op)
    }

    /// Between steps, with `room` simulated seconds left: the end of the simulation and gets
    /// once the budget or the stop time is reached (`Err`), else the step size, at most `room`:
    /// mostly the sequence's, sometimes another of 0.1 to 10 ms.
    pub fn step_size(&self, rng: &mut Rng, m: &Description, room: f64) -> Result<f64, O> {
        if room < 1e-6 {
            return Err(match rng.below(10) {
                0..=5 => O::get_reals(rng, m),
                6..=8 => O::TERMINATE,
                _ => O::RESET,
            });
        }
        Ok(if rng.chance(0.8) { self.h } else { rng.log_uniform(1e-4, 1e-2) }.min(room))
    }

    /// Queues `ops` for `phase`, an FMU state round trip after them, and returns the first.
    pub fn plan_with_round_trip(&mut self, phase: Phase, ops: Vec<O>) -> Option<O> {
        self.round_trip.start();
        self.plan(phase, ops)
    }

    /// Queues `ops` for `phase` and returns the first.
    pub fn plan(&mut self, phase: Phase, ops: Vec<O>) -> Option<O> {
        self.queue.extend(ops.into_iter().map(|op| (phase, op)));
        self.queue.pop_front().map(|(_, op)| op)
    }

    /// An FMU state call that starts a round trip.
    pub fn start_round_trip(&mut self, rng: &mut Rng, s: &Bookkeeping) -> O {
        self.round_trip.start();
        state_op(rng, s)
    }

    /// The first call of the spool probe with a step of `h` (`None` for a model without it).
    pub fn spool(&mut self, rng: &mut Rng, s: &Bookkeeping, h: f64) -> Option<O> {
        let probe = probes::spool(rng, s.model, &s.view, h);
        self.probe(Phase::StepComplete, probe, s.model)
    }

    /// Model Exchange in Continuous-Time Mode, as an integrator drives it (`Ok`): terminated (or
    /// reset) after 1 s, a probe's call, time forward by up to the sequence's step, states near
    /// the last ones read, derivatives, event indicators, completed steps, continuous inputs;
    /// else (`Err`) a roll from 78 to 99 for the version's other calls.
    pub fn integrator(&mut self, rng: &mut Rng, s: &Bookkeeping) -> Result<O, usize> {
        let m = s.model;
        if !(s.view.time < 1.0) {
            return Ok(if rng.chance(0.7) { O::TERMINATE } else { O::RESET });
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
            return Ok(op);
        }
        Ok(match rng.below(100) {
            0..=19 => O::probe(Probe::SetTime(s.view.time + self.h * rng.uniform(0.0, 1.0)), m),
            20..=34 if s.x.len() == m.states => {
                let x = s.x.iter().map(|x| x + (1e-6 + 1e-4 * x.abs()) * rng.uniform(-1.0, 1.0)).collect();
                O::probe(Probe::SetContinuousStates(x), m)
            }
            20..=34 => O::probe(Probe::GetContinuousStates, m),
            35..=59 => O::get_derivatives(m),
            60..=64 => O::probe(Probe::GetEventIndicators, m),
            65..=69 => O::completed_integrator_step(rng.chance(0.9)),
            70..=77 => O::set(rng, m, &m.real_inputs).unwrap_or_else(|| O::get_reals(rng, m)),
            roll => return Err(roll),
        })
    }

    /// The next call: the plan's, else one drawn for the instance's phase.
    pub fn next<'a, S: Deref<Target = Bookkeeping<'a>>>(&mut self, rng: &mut Rng, s: &S) -> O
    where
        Self: Phases<S, O>,
    {
        if let Some(op) = self.queued(s) {
            return op;
        }
        let m = s.model;
        match s.view.phase {
            Phase::Instantiated | Phase::Initialization => self.initialization(rng, s),
            Phase::StepComplete => self.stepping(rng, s),
            Phase::EventMode => self.event_mode(rng, s).unwrap_or_else(|| match rng.below(12) {
                0..=5 => O::ENTER_CONTINUOUS_TIME_MODE,
                6 => O::UPDATE_DISCRETE_STATES,
                7 => O::set(rng, m, &m.step_settable).unwrap_or(O::ENTER_CONTINUOUS_TIME_MODE),
                8 => O::get_reals(rng, m),
                9 => O::probe(Probe::GetContinuousStates, m),
                10 => state_op(rng, s),
                _ => O::TERMINATE,
            }),
            Phase::ContinuousTime => self.integrating(rng, s),
            Phase::StepFailed => self.step_failed(rng, s),
            Phase::Terminated => match rng.below(4) {
                0 => O::get_reals(rng, m),
                1 => state_op(rng, s),
                _ => O::RESET,
            },
            Phase::Unknown => self.unknown(rng, s),
            Phase::Broken => {
                // From now on, plans keep the start values.
                self.tame = true;
                O::RESET
            }
        }
    }
}

/// An FMU state call of an importer: get a new one, overwrite, restore, serialize (size first),
/// deserialize intact bytes (or, now and then, damaged ones), free.
fn state_call(rng: &mut Rng, states: &FmuStates) -> StateCall {
    let live = rng.choose(&states.live);
    match (rng.below(8), live) {
        (1, Some(l)) => StateCall::Get { state: Slot::Holding(l.ptr) },
        (2, Some(l)) => StateCall::Set { state: l.ptr },
        (3..=4, Some(l)) => match l.size {
            Some(size) => StateCall::Serialize { state: l.ptr, size, null_buffer: false },
            None => StateCall::Size { state: l.ptr, null_size: false },
        },
        (5, _) if !states.saved.is_empty() => {
            StateCall::Deserialize { bytes: rng.pick(&states.saved).intact(), null_state: false }
        }
        (6, _) if !states.saved.is_empty() => StateCall::Deserialize { bytes: blob(rng, states), null_state: false },
        (7, Some(l)) => StateCall::Free { state: Slot::Holding(l.ptr) },
        _ => StateCall::Get { state: Slot::Holding(null_mut()) },
    }
}

/// An FMU state call of an importer (`state_call`) as the version's op.
pub fn state_op<O: Call>(rng: &mut Rng, s: &Bookkeeping) -> O {
    O::state(state_call(rng, &s.states))
}

/// The unknowns, knowns and seeds of a directional derivative, seeds of order one: one to three
/// outputs or `der(...)` derivatives on one or two Real inputs; in Initialization Mode
/// (`initialization`), InitialUnknowns on inputs and initial="exact" variables.
pub fn plausible_derivative(rng: &mut Rng, m: &Description, initialization: bool) -> (Vec<u32>, Vec<u32>, Vec<f64>) {
    let inputs: Vec<u32> = m.real_inputs.iter().map(|&i| m.variables[i].vr).collect();
    let unknown_pool =
        if initialization { m.initial_unknowns.clone() } else { [&m.outputs[..], &m.derivatives].concat() };
    let known_pool = if initialization { &m.initial_knowns } else { &inputs };
    let unknowns: Vec<u32> = (0..rng.range(1, 3)).filter_map(|_| rng.choose(&unknown_pool).copied()).collect();
    let knowns: Vec<u32> = (0..rng.range(1, 2)).filter_map(|_| rng.choose(known_pool).copied()).collect();
    let seeds = knowns.iter().map(|_| rng.uniform(-1.0, 1.0)).collect();
    (unknowns, knowns, seeds)
}

/// One to three variables of one type from `candidates` (indices) with values in range (as
/// f64: Integer rounded, Boolean 0 or 1; none for String): the type, references and values.
pub fn plausible_values(rng: &mut Rng, m: &Description, candidates: &[usize]) -> Option<(Type, Vec<u32>, Vec<f64>)> {
    let first = &m.variables[*rng.choose(candidates)?];
    let mut vars = vec![first];
    for _ in 0..rng.below(3) {
        let v = &m.variables[*rng.pick(candidates)];
        if v.ty == first.ty {
            vars.push(v);
        }
    }
    let values = vars.iter().map(|v| v.plausible(rng)).collect();
    Some((first.ty, vars.iter().map(|v| v.vr).collect(), values))
}

/// The outputs, a few Reals, or every Real.
pub fn some_reals(rng: &mut Rng, m: &Description) -> Vec<u32> {
    let reals = m.of_type(Type::Real);
    match rng.below(10) {
        0..=2 if !m.outputs.is_empty() => m.outputs.clone(),
        0..=6 => (0..rng.range(1, 8)).filter_map(|_| rng.choose(reals).copied()).collect(),
        _ => reals.to_vec(),
    }
}

/// The experiment of fmi2SetupExperiment and fmi3EnterInitializationMode.
#[derive(Debug, Clone, Copy)]
pub struct Experiment {
    pub tolerance_defined: bool,
    pub tolerance: f64,
    pub start: f64,
    pub stop_defined: bool,
    pub stop: f64,
}

/// An experiment as an importer sets it up: start mostly 0 (sometimes far from it, where the
/// time's resolution is coarse), a tolerance, sometimes a stop time.
pub fn plausible_experiment(rng: &mut Rng) -> Experiment {
    let start = match rng.below(20) {
        0..=15 => 0.0,
        16..=17 => rng.uniform(0.0, 100.0),
        18 => 1e6,
        _ => 1e9,
    };
    Experiment {
        tolerance_defined: rng.chance(0.5),
        tolerance: rng.log_uniform(1e-8, 1e-4),
        start,
        stop_defined: rng.chance(0.3),
        stop: start + rng.uniform(0.05, 1.0),
    }
}
