//! The calls of a clock master for an FMU with a time-based input Clock (FMI 3.0 only;
//! ClockedPressureFeedbackController), as `planner3` plans them for it between initialisation
//! (the shared plan) and the end: after fmi3ExitInitializationMode, in Event Mode,
//! fmi3UpdateDiscreteStates and fmi3EnterStepMode (Co-Simulation) or fmi3EnterContinuousTimeMode
//! (Model Exchange); then steps or fmi3SetTime up to the next activation time t_k exactly,
//! fmi3EnterEventMode, fmi3SetClock, the clocked inputs set, the clocked outputs read,
//! fmi3UpdateDiscreteStates, back to Step or Continuous-Time Mode; with the usual FMU state calls,
//! tunable parameters, terminations and resets, and now and then (`MISUSE`) what `clock_rules`
//! forbids: a step from or past t_k without the activation, fmi3SetTime past it, the Clock set
//! again after the instant ended or at another time, clocked variables while it is inactive.

use crate::clock_rules::Place;
use crate::model_description::{Clock, Description, Type};
use crate::ops::Arr;
use crate::ops3::Op3;
use crate::planner::{state_op, Planned, Planner};
use crate::probes::{time_back, Probe};
use crate::rng::Rng;
use crate::session3::Session3;
use crate::view::{Phase, View};

/// The chance of a call the clock rules forbid where the master would do the right thing.
const MISUSE: f64 = 0.03;
/// Simulated seconds of a Model Exchange sequence (its time is the master's).
const ME_SECONDS: f64 = 0.5;

/// The model's Clock (the planner calls these functions for models with one only).
fn clock(m: &Description) -> &Clock {
    m.clock.as_ref().expect("the clock master plans for models with a Clock")
}

/// The time of the activation due, and whether the instance is at it.
fn at_due(c: &Clock, v: &View) -> (f64, bool) {
    let t_due = c.time(v.start, v.activations);
    (t_due, c.place(v.start, v.time) == Place::On(v.activations))
}

/// Co-Simulation in Step Mode: steps up to the next activation and Event Mode there; now and
/// then a step past it.
pub fn stepping(p: &mut Planner<Op3>, rng: &mut Rng, s: &Session3) -> Op3 {
    let (m, v) = (s.model, &s.view);
    let room = v.room(s.budget());
    let (t_due, due) = at_due(clock(m), v);
    if room < 1e-6 {
        return end(rng, m);
    }
    let step = |h: f64, rng: &mut Rng| Op3::DoStep { t: v.time, h, no_set_prior: rng.chance(0.9), null_outputs: false };
    if due {
        return if rng.chance(MISUSE) {
            step(p.step_size(rng, m, room).unwrap_or(room), rng)
        } else {
            Op3::EnterEventMode
        };
    }
    let h = p.step_size(rng, m, room).unwrap_or(room);
    match rng.below(100) {
        // To t_k exactly where the step would pass it.
        0..=54 => step(h.min(t_due - v.time), rng),
        55..=57 => step(t_due - v.time + clock(m).interval * rng.uniform(0.01, 1.0), rng),
        58..=69 => Op3::set(rng, m, &m.step_settable).unwrap_or_else(|| unclocked_reals(rng, m)),
        70..=79 => unclocked_reals(rng, m),
        80..=86 => state_op(rng, s),
        87 => p.start_round_trip(rng, s),
        88..=90 => Op3::EnterEventMode,
        91..=92 => clocked_access(rng, m),
        _ => unclocked_reals(rng, m),
    }
}

/// Model Exchange in Continuous-Time Mode: the time up to the next activation and Event Mode
/// there, completed integrator steps, the time set back with an FMU state round trip; now and then
/// the time set past the activation.
pub fn integrating(p: &mut Planner<Op3>, rng: &mut Rng, s: &Session3) -> Op3 {
    let (m, v) = (s.model, &s.view);
    if !(v.time - v.start < ME_SECONDS) {
        return end(rng, m);
    }
    let (t_due, due) = at_due(clock(m), v);
    let past = |rng: &mut Rng| Op3::SetTime { t: t_due + clock(m).interval * rng.uniform(0.01, 1.0) };
    if due {
        return if rng.chance(MISUSE) { past(rng) } else { Op3::EnterEventMode };
    }
    let h = p.step_size(rng, m, f64::INFINITY).unwrap_or(1e-3);
    match rng.below(100) {
        0..=49 => Op3::SetTime { t: if v.time + h >= t_due { t_due } else { v.time + h } },
        50..=59 => Op3::completed_integrator_step(rng.chance(0.9)),
        60..=64 => {
            let back = time_back(rng, v, h).into_iter().map(|probe| Op3::probe(probe, m)).collect();
            p.plan_with_round_trip(Phase::ContinuousTime, back).unwrap_or_else(|| unclocked_reals(rng, m))
        }
        65..=72 => unclocked_reals(rng, m),
        73..=79 => state_op(rng, s),
        80..=82 => Op3::EnterEventMode,
        83..=85 => past(rng),
        86..=87 => clocked_access(rng, m),
        88..=91 => Op3::probe(Probe::GetEventIndicators, m),
        92..=95 => Op3::GetNumberOfContinuousStates { null: false },
        _ => Op3::get_derivatives(m),
    }
}

/// Event Mode: at the activation due, its instant (fmi3SetClock, inputs, outputs,
/// fmi3UpdateDiscreteStates) and back; elsewhere the end of the event, or other calls.
pub fn event_mode(p: &mut Planner<Op3>, rng: &mut Rng, s: &Session3) -> Op3 {
    let (m, v) = (s.model, &s.view);
    let (_, due) = at_due(clock(m), v);
    let leave = if s.me { Op3::EnterContinuousTimeMode } else { Op3::EnterStepMode };
    let update = Op3::UpdateDiscreteStates { null_flags: false };
    let mut ops = Vec::new();
    if v.clock_active || (due && !rng.chance(MISUSE)) {
        if !v.clock_active {
            ops.push(set_clock(m));
        }
        ops.extend(instant(rng, s));
        ops.push(update);
        if rng.chance(MISUSE) {
            // A double activation.
            ops.push(set_clock(m));
        }
        ops.push(leave);
    } else {
        match rng.below(50) {
            // At no activation time, one made or (after the misuse above) the one due.
            0 => ops.push(set_clock(m)),
            1 => ops.push(clocked_access(rng, m)),
            2..=3 => ops.push(state_op(rng, s)),
            4..=5 => ops.push(unclocked_reals(rng, m)),
            6 => ops.push(Op3::Terminate),
            7..=8 => ops.extend(Op3::set(rng, m, &m.step_settable)),
            _ => ops.extend([update, leave]),
        }
    }
    p.plan(Phase::EventMode, ops).unwrap_or(Op3::Reset)
}

/// The calls of an activation's instant after fmi3SetClock: the clocked inputs set (now and
/// then again), the clocked outputs (and locals) read, the Clock read or set again (the same
/// activation), an FMU state.
fn instant(rng: &mut Rng, s: &Session3) -> Vec<Op3> {
    let m = s.model;
    let mut ops = Vec::new();
    for (chance, op) in [(0.9, Call::SetInputs), (0.2, Call::GetClock), (0.1, Call::SetClock), (0.8, Call::GetOutputs)]
    {
        if rng.chance(chance) {
            ops.push(call(op, rng, m));
        }
    }
    if rng.chance(0.1) {
        ops.extend([call(Call::SetInputs, rng, m), call(Call::GetOutputs, rng, m)]);
    }
    if rng.chance(0.05) {
        ops.push(state_op(rng, s));
    }
    ops
}

/// The calls of an instant.
#[derive(Clone, Copy)]
enum Call {
    SetInputs,
    GetOutputs,
    GetClock,
    SetClock,
}

fn call(call: Call, rng: &mut Rng, m: &Description) -> Op3 {
    match call {
        Call::SetInputs => {
            let candidates = clocked(m, &["input"]);
            Op3::set(rng, m, &candidates).unwrap_or_else(|| unclocked_reals(rng, m))
        }
        Call::GetOutputs => {
            let causalities: &[&str] = if rng.chance(0.3) { &["output", "local"] } else { &["output"] };
            let vr: Vec<u32> = clocked(m, causalities).iter().map(|&i| m.variables[i].vr).collect();
            Op3::GetFloat64 { n_values: vr.len(), vr: Arr::Items(vr), null_values: false }
        }
        Call::GetClock => Op3::GetClock { vr: Arr::Items(vec![clock(m).vr]), null_values: false },
        Call::SetClock => set_clock(m),
    }
}

/// fmi3SetClock of the Clock to active.
fn set_clock(m: &Description) -> Op3 {
    Op3::SetClock { vr: Arr::Items(vec![clock(m).vr]), values: Arr::Items(vec![1]) }
}

/// Indices of the clocked Reals of these causalities.
fn clocked(m: &Description, causalities: &[&str]) -> Vec<usize> {
    let wanted = |i: &usize| {
        let v = &m.variables[*i];
        v.clocked && v.ty == Type::Real && causalities.contains(&v.causality.as_str())
    };
    (0..m.variables.len()).filter(wanted).collect()
}

/// A clocked variable set or read while the Clock is inactive (the misuse `clock_rules` forbids).
fn clocked_access(rng: &mut Rng, m: &Description) -> Op3 {
    call(if rng.chance(0.5) { Call::SetInputs } else { Call::GetOutputs }, rng, m)
}

/// A read of one to all the Reals that are not clocked (parameters, time).
fn unclocked_reals(rng: &mut Rng, m: &Description) -> Op3 {
    let reals: Vec<u32> =
        m.of_type(Type::Real).iter().copied().filter(|&r| m.variable(r).is_some_and(|v| !v.clocked)).collect();
    let vr: Vec<u32> = match rng.below(3) {
        0 => reals,
        _ => (0..rng.range(1, 4)).filter_map(|_| rng.choose(&reals).copied()).collect(),
    };
    Op3::GetFloat64 { n_values: vr.len(), vr: Arr::Items(vr), null_values: false }
}

/// The end of the simulation: terminated, reset, or a read.
fn end(rng: &mut Rng, m: &Description) -> Op3 {
    match rng.below(10) {
        0..=5 => Op3::Terminate,
        6..=8 => Op3::Reset,
        _ => unclocked_reals(rng, m),
    }
}
