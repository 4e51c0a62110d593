//! Linear models of an FMU model through its own directional derivatives
//! ([`Model::directional_derivative`], what fmi2GetDirectionalDerivative returns to an importer):
//! HydraulicCircuit with its plain port (`boomsim linearize --model HydraulicCircuit`), whose
//! inputs are the spool reference and the port's stroke and velocity.

use super::linearize::{plant_point, unit_of, LinearModel, Signal};
use boomsim::fmu::{Causality, Model, Seeds, Value, Values};
use boomsim::hydraulics::circuit::N_STATES as N_CIRCUIT;
use boomsim::models::HydraulicCircuit;
use nalgebra::DMatrix;

/// The inputs of HydraulicCircuit's linear model: the spool reference and the plain port's
/// stroke and velocity from the mechanics.
pub const CIRCUIT_INPUTS: [&str; 3] = ["valve.u_ref", "cylinder.x", "cylinder.v"];
/// Its outputs unless others are asked for: the force on the rod (what the mechanics receive)
/// and the chamber pressures.
pub const CIRCUIT_OUTPUTS: [&str; 3] = ["cylinder.F", "p3", "p4"];

/// `M`'s variable `name` with its unit, refusing a name that is not of `causality`.
fn signal<M: Model>(name: &str, causality: &[Causality]) -> Result<(u32, Signal), String> {
    let v = M::VARIABLES
        .iter()
        .find(|v| v.name == name && causality.contains(&v.causality))
        .ok_or_else(|| format!("{} has no {causality:?} variable \"{name}\"", M::INFO.identifier))?;
    Ok((v.vr, Signal { name: v.name.to_string(), unit: unit_of(v) }))
}

/// The linear model of `model` at its continuous states and the inputs in `values`: one
/// directional derivative per state and per input, seeded with 1, into every state derivative
/// and output.
pub fn through_directional_derivatives<M: Model>(
    model: &M,
    values: &Values,
    inputs: &[&str],
    outputs: &[&str],
) -> Result<LinearModel, String> {
    let states: Vec<(u32, Signal)> = M::STATES
        .iter()
        .map(|s| M::VARIABLES.iter().find(|v| v.vr == s.state).expect("a state variable").name)
        .map(|name| signal::<M>(name, &[Causality::Output, Causality::Local]))
        .collect::<Result<_, _>>()?;
    let ins: Vec<(u32, Signal)> =
        inputs.iter().map(|n| signal::<M>(n, &[Causality::Input])).collect::<Result<_, _>>()?;
    let outs: Vec<(u32, Signal)> =
        outputs.iter().map(|n| signal::<M>(n, &[Causality::Output, Causality::Local])).collect::<Result<_, _>>()?;
    let (n, m, p) = (states.len(), ins.len(), outs.len());
    let unknowns: Vec<u32> = M::STATES.iter().map(|s| s.derivative).chain(outs.iter().map(|o| o.0)).collect();
    let mut column = vec![0.0; n + p];
    let (mut a, mut b, mut c, mut d) =
        (DMatrix::zeros(n, n), DMatrix::zeros(n, m), DMatrix::zeros(p, n), DMatrix::zeros(p, m));
    for (k, known) in states.iter().chain(&ins).enumerate() {
        let seeds = Seeds { knowns: &[(known.0, 1.0)], unknowns: &unknowns, out: &mut column };
        model.directional_derivative(values, seeds)?;
        let (top, bottom, col) = if k < n { (&mut a, &mut c, k) } else { (&mut b, &mut d, k - n) };
        for i in 0..n {
            top[(i, col)] = column[i];
        }
        for j in 0..p {
            bottom[(j, col)] = column[n + j];
        }
    }
    let mut x0 = vec![0.0; n];
    model.continuous_states(&mut x0);
    let mut y = values.clone();
    model.outputs(&mut y);
    Ok(LinearModel {
        u0: ins.iter().map(|i| values.real(i.0)).collect(),
        y0: outs.iter().map(|o| y.real(o.0)).collect(),
        states: states.into_iter().map(|s| s.1).collect(),
        inputs: ins.into_iter().map(|s| s.1).collect(),
        outputs: outs.into_iter().map(|s| s.1).collect(),
        a,
        b,
        c,
        d,
        x0,
    })
}

/// HydraulicCircuit (plain port) at the HydraulicBoom's steady lowering at `u_ref` through
/// `stroke` with the parameter `changes` (the hydraulic ones reach the circuit; the boom's set
/// the stroke's velocity and load): the circuit's states there, the port's inputs at the boom's
/// stroke and velocity.
pub fn circuit_model(
    changes: &[(&str, Value)],
    u_ref: f64,
    stroke: f64,
    outputs: &[&str],
) -> Result<LinearModel, String> {
    let (plant, x, velocity) = plant_point(changes, u_ref, stroke)?;
    let mut values = Values::new(HydraulicCircuit::VARIABLES);
    for (name, v) in changes {
        if let Some(i) = HydraulicCircuit::VARIABLES.iter().position(|x| x.name == *name) {
            values.put(i, v.clone());
        }
    }
    let f = plant.circuit.evaluate(x[..N_CIRCUIT].try_into().expect("circuit"), u_ref, stroke, velocity).force;
    for (name, value) in
        [("start.x", stroke), ("start.F", f), ("valve.u_ref", u_ref), ("cylinder.x", stroke), ("cylinder.v", velocity)]
    {
        let i = HydraulicCircuit::VARIABLES.iter().position(|x| x.name == name).expect("a HydraulicCircuit variable");
        values.put(i, Value::Real(value));
    }
    let mut model = HydraulicCircuit::initialize(&values)?;
    model.set_continuous_states(&x[..N_CIRCUIT])?;
    through_directional_derivatives(&model, &values, &CIRCUIT_INPUTS, outputs)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::linearize::linearize;
    use boomsim::scalar::Dual64;

    /// HydraulicCircuit's linear model, from its FMU's directional derivatives, joined to the
    /// rigid boom's linearised motion `m(x) a = F - ...` (its accelerations in dual numbers) is
    /// the HydraulicBoom's linear model at the same steady lowering, entry by entry: the circuit
    /// cut at the rod and put back together (the port's stroke and velocity are the boom's
    /// states, its force the boom's input). Within 1e-9 of each row's largest entry: round-off.
    #[test]
    fn circuit_and_boom_joined_are_the_hydraulic_boom() {
        let rigid = [("boom.flexible", Value::Boolean(false))];
        let (u_ref, stroke) = (-0.05, 0.25);
        let (plant, x, v) = plant_point(&rigid, u_ref, stroke).unwrap();
        let boom = linearize(&plant, &x, u_ref, &["p4"]).unwrap();
        let circuit = circuit_model(&rigid, u_ref, stroke, &["cylinder.F"]).unwrap();
        // The force at the point and the acceleration's partials in x, v (force held) and F.
        let f0 = circuit.y0[0];
        let acceleration = |seed: [f64; 3]| {
            let (xs, vs, fs) = (Dual64::new(stroke, seed[0]), Dual64::new(v, seed[1]), Dual64::new(f0, seed[2]));
            let mut a = [Dual64::from(0.0)];
            plant.boom.kinetics::<Dual64>().accelerations(&[xs], &[vs], &mut |_, _| fs, &mut a);
            a[0].eps
        };
        let [da_dx, da_dv, da_df] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].map(acceleration);
        let n = N_CIRCUIT;
        let mut a = DMatrix::zeros(n + 2, n + 2);
        a.view_mut((0, 0), (n, n)).copy_from(&circuit.a);
        a.view_mut((0, n), (n, 2)).copy_from(&circuit.b.columns(1, 2));
        a[(n, n + 1)] = 1.0;
        for j in 0..n {
            a[(n + 1, j)] = da_df * circuit.c[(0, j)];
        }
        a[(n + 1, n)] = da_dx + da_df * circuit.d[(0, 1)];
        a[(n + 1, n + 1)] = da_dv + da_df * circuit.d[(0, 2)];
        for i in 0..n + 2 {
            let scale = boom.a.row(i).amax();
            for j in 0..n + 2 {
                assert!(
                    (a[(i, j)] - boom.a[(i, j)]).abs() <= 1e-9 * scale,
                    "A[{i}, {j}]: {} vs {}",
                    a[(i, j)],
                    boom.a[(i, j)]
                );
            }
        }
        // The spool reference enters through the circuit alone.
        for i in 0..n {
            assert!((circuit.b[(i, 0)] - boom.b[(i, 0)]).abs() <= 1e-9 * boom.b.amax());
        }
    }
}
