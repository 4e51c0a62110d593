//! The PressureFeedbackController FMU model: the high-pass filtered pressure feedback of thesis
//! section 6.1 ([`crate::control::pressure_feedback`]) with operator reference and output limits.
//!
//! The fed-back pressure over a step is a [`Ramp`]: its value at the step start and the slope the
//! master passes with fmi2SetRealInputDerivatives (0: held). With `p.extrapolation` a step without
//! a slope takes it from the last two received samples, `(p_k - p_k-1) / (t_k - t_k-1)`, and the
//! outputs after the step use `p_k + slope h` until the master sets the next sample: a Jacobi
//! master, which steps plant and controller from the values at t_k and reads u before it passes
//! p_k+1, then gets the command of the Gauss-Seidel order (plant first, controller with the
//! slope of p over the step) to second order in h.

use super::port::Ramp;
use crate::control::{HighPassFeedback, FEEDBACK_PARAMS};
use crate::fmu::driver::Step;
use crate::fmu::instance::bounded_slope;
use crate::fmu::{ContinuousState, Log, Model, ModelInfo, StepError, StepStart, Values, Variable};
use crate::params::build;

/// Value references (stable across releases).
pub mod vr {
    pub const U_REF: u32 = 0;
    pub const P: u32 = 1;
    pub const U: u32 = 2;
    pub const U_COMP: u32 = 3;
    /// `K_F + k` is [`crate::control::FEEDBACK_PARAMS`]`[k]`.
    pub const K_F: u32 = 4;
    pub const OMEGA_F: u32 = 5;
    pub const Q_RATED: u32 = 6;
    pub const ENABLE: u32 = 7;
    pub const U_MIN: u32 = 8;
    pub const U_MAX: u32 = 9;
    pub const P_LP: u32 = 10;
    pub const EXTRAPOLATION: u32 = 11;
    pub const DER_P_LP: u32 = 12;
    /// The clocked controller's ([`super::super::clocked_pressure_feedback_controller`]): its
    /// Clock, pressure sample and the previous values of its clocked states.
    pub const SAMPLE: u32 = 13;
    pub const P_SAMPLE: u32 = 14;
    pub const P_LP_PREVIOUS: u32 = 15;
    pub const P_SAMPLE_PREVIOUS: u32 = 16;
}

/// Admissible fed-back pressure: +-1000 bar gauge, far beyond the PVG32's 350 bar rating and
/// absolute zero, so that only nonsense is refused. Below absolute zero because the plants'
/// pressures are continued there for an integrator's trial states ([`crate::hydraulics::line`]):
/// with plant and controller in one Model Exchange system, CVode's trial state of the plant is
/// the controller's input (U at rtol 1e-4 gave p4 = -110664 Pa gauge), and the filter is linear,
/// defined for any pressure.
const P_RANGE: (f64, f64) = (-1e8, 1e8);

/// The rows the clocked controller ([`super::clocked_pressure_feedback_controller`]) shares, with
/// the same value references.
pub(super) mod row {
    use super::{vr, P_RANGE};
    use crate::control::FEEDBACK_PARAMS;
    use crate::fmu::Variable;
    use crate::params::{ParamSpec, ParamType};

    pub const U_REF: Variable = Variable::real_input(
        "u_ref",
        vr::U_REF,
        0.0,
        "1",
        "%",
        (-1.0, 1.0),
        "Operator's spool reference; < 0 lowers the load",
    );
    pub const P: Variable = Variable::real_input(
        "p",
        vr::P,
        0.0,
        "Pa",
        "bar",
        P_RANGE,
        "Fed-back pressure (p4, rod side / CBV pilot), gauge",
    );
    pub const U: Variable =
        Variable::real_output("u", vr::U, "1", "%", "Spool command u = clamp(u_ref + u_comp, u_min, u_max)");
    pub const U_COMP: Variable =
        Variable::real_output("u_comp", vr::U_COMP, "1", "%", "Compensation u_comp = G_f(s) p / Q_rated (eq. 6.2)");
    pub const K_F: Variable = Variable::param(vr::K_F, FEEDBACK_PARAMS[0].spec);
    pub const OMEGA_F: Variable = Variable::param(vr::OMEGA_F, FEEDBACK_PARAMS[1].spec);
    pub const Q_RATED: Variable = Variable::param(vr::Q_RATED, FEEDBACK_PARAMS[2].spec).fixed();
    pub const ENABLE: Variable =
        Variable::bool_param("enable", vr::ENABLE, true, "Feedback on; off gives u = u_ref (experiment U)");
    pub const U_MIN: Variable = Variable::param(
        vr::U_MIN,
        ParamSpec {
            name: "u_min",
            default: -1.0,
            unit: "1",
            display_unit: "%",
            min: -1.0,
            max: 1.0,
            description: "Lower limit of the spool command",
            source: "Full spool opening in the lowering direction (eq. 2.44)",
            ty: ParamType::Real,
        },
    );
    pub const U_MAX: Variable = Variable::param(
        vr::U_MAX,
        ParamSpec {
            name: "u_max",
            default: 1.0,
            unit: "1",
            display_unit: "%",
            min: -1.0,
            max: 1.0,
            description: "Upper limit of the spool command",
            source: "Full spool opening in the lifting direction (eq. 2.44)",
            ty: ParamType::Real,
        },
    );
    pub const P_LP: Variable = Variable::real_local(
        "filter.p_lp",
        vr::P_LP,
        "Pa",
        "bar",
        "Filter state: low-passed pressure x, x' = omega_f (p - x)",
    );
}

const VARIABLES: &[Variable] = &[
    row::U_REF,
    row::P,
    // The filter starts at rest at the initial p (u_comp = 0): in Initialization Mode u depends
    // on u_ref only.
    row::U.depends(&[vr::U_REF, vr::P]).initial_depends(&[vr::U_REF]),
    row::U_COMP.depends(&[vr::P]).initial_depends(&[]),
    row::K_F,
    row::OMEGA_F,
    row::Q_RATED,
    row::ENABLE,
    row::U_MIN,
    row::U_MAX,
    row::P_LP,
    Variable::bool_param(
        "p.extrapolation",
        vr::EXTRAPOLATION,
        false,
        "Without an input derivative of p, extrapolate p linearly through its last two received samples (for Jacobi masters: libcosim, ecos, fmpy's SSP simulator); false holds p over a step",
    )
    .fixed(),
    Variable::real_local(
        "der(filter.p_lp)",
        vr::DER_P_LP,
        "Pa/s",
        "bar/s",
        "Time derivative of the continuous state (Model Exchange)",
    ),
];

/// Model Exchange: the filter state, nominal 1 bar.
const STATES: &[ContinuousState] = &[ContinuousState { state: vr::P_LP, derivative: vr::DER_P_LP, nominal: 1e5 }];

const DOCUMENTATION: &str = r#"<p>High-pass filtered pressure feedback of thesis section 6.1 (Fig. 6.1, 6.2).
The fed-back pressure <i>p</i> (p4) passes G<sub>f</sub>(s) = K<sub>f</sub> s / (s/&omega;<sub>f</sub> + 1) (eq. 6.2),
giving a flow Q<sub>f</sub> [m&sup3;/s]; the pressure-compensated valve turns it into spool opening with its rated flow
Q<sub>rated</sub> (25 l/min per unit opening): u<sub>comp</sub> = Q<sub>f</sub>/Q<sub>rated</sub>,
u = clamp(u<sub>ref</sub> + u<sub>comp</sub>, u<sub>min</sub>, u<sub>max</sub>).
A falling pressure opens the valve further in the lowering direction (u &lt; 0), a rising one closes it.</p>
<p>Realisation: x' = &omega;<sub>f</sub>(p &minus; x), Q<sub>f</sub> = K<sub>f</sub>&omega;<sub>f</sub>(p &minus; x), advanced exactly
for inputs that are constant or linear over a step (set the slope with fmi2SetRealInputDerivatives, order 1), so any
communication step gives the same result. Masters that step all FMUs from the values at the same communication
point (Jacobi: libcosim, ecos, fmpy's SSP simulator) pass no slope and read <i>u</i> before they pass the new
<i>p</i>: with <code>p.extrapolation</code> = true the controller then extrapolates <i>p</i> through its last two
received samples over the step and for the outputs at its end, which gives the command of a master that steps the
plant first and passes the slope (default false: <i>p</i> held). The filter starts at rest at the initial pressure
(x = p at the end of initialisation): no kick at t = 0. Defaults: experiment B (K<sub>f</sub> = 1.24e-11 m<sup>4</sup>s<sup>2</sup>/kg,
&omega;<sub>f</sub> = 35.8 rad/s, Table 7.2).</p>"#;

/// The controller's tunable parameters: the filter of eq. 6.2, the switch and the command's
/// limits (shared with the clocked controller).
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Settings {
    pub feedback: HighPassFeedback,
    pub enable: bool,
    pub u_min: f64,
    pub u_max: f64,
}

impl Settings {
    /// The parameters' values; refuses limits that leave no command.
    pub fn read(values: &Values) -> Result<Self, String> {
        let (u_min, u_max) = (values.real(vr::U_MIN), values.real(vr::U_MAX));
        if u_min >= u_max {
            return Err(format!("u_min = {u_min} must be less than u_max = {u_max}"));
        }
        let feedback = build(HighPassFeedback::default(), &FEEDBACK_PARAMS, |k| values.real(vr::K_F + k as u32));
        Ok(Settings { feedback, enable: values.boolean(vr::ENABLE), u_min, u_max })
    }

    /// (u_comp, unclamped u) for the reference `u_ref`, pressure `p` and filter state `x`.
    pub fn command(&self, u_ref: f64, p: f64, x: f64) -> (f64, f64) {
        let u_comp = if self.enable { self.feedback.u_comp(p, x) } else { 0.0 };
        (u_comp, u_ref + u_comp)
    }

    /// Logs a command beyond the limits (`logSaturation`) at time `t`.
    pub fn log_saturation(&self, u: f64, t: f64, log: &mut dyn Log) {
        if u < self.u_min || u > self.u_max {
            let (lo, hi) = (self.u_min, self.u_max);
            log.info("logSaturation", &format!("t = {t}: u_ref + u_comp = {u} clamped to [{lo}, {hi}]"));
        }
    }
}

/// The controller's parameters, filter state and fed-back pressure.
#[derive(Debug, Clone, PartialEq)]
pub struct PressureFeedbackController {
    settings: Settings,
    /// `p.extrapolation`.
    extrapolate: bool,
    /// Low-passed pressure x [Pa].
    x: f64,
    /// Time of `x` (the end of the last step).
    t: f64,
    /// The pressure over the last step: its sample at the step start and the slope used.
    p: Ramp,
    /// Whether `p` holds a received sample (false before the first step).
    sampled: bool,
    /// Whether the master set p since the last step (a sample at the current time).
    fresh: bool,
}

impl PressureFeedbackController {
    /// The controller with filter state `x`, at rest at the current input p.
    fn from_values(values: &Values, x: f64) -> Result<Self, String> {
        let c = PressureFeedbackController {
            settings: Settings::read(values)?,
            extrapolate: values.boolean(vr::EXTRAPOLATION),
            x,
            t: 0.0,
            p: Ramp::new(0.0, values.real(vr::P), 0.0),
            sampled: false,
            fresh: true,
        };
        Ok(c)
    }

    /// The fed-back pressure now: the extrapolated one after a step until the master sets the
    /// next sample, else the input.
    fn pressure(&self, values: &Values) -> f64 {
        if self.extrapolate && self.sampled && !self.fresh {
            self.p.at(self.t)
        } else {
            values.real(vr::P)
        }
    }

    /// (u_comp, unclamped u) for pressure `p`.
    fn command(&self, values: &Values, p: f64) -> (f64, f64) {
        self.settings.command(values.real(vr::U_REF), p, self.x)
    }

    /// The pressure over the step from `t` of length `h`: the input with the master's slope;
    /// with `p.extrapolation` and no slope, a new sample with the slope through the previous one,
    /// or, if the master set none since the last step, the last ramp continued. An extrapolated
    /// ramp that would leave p's declared range within the step stops at the bound
    /// ([`bounded_slope`], as the FMI layer bounds a master's slope), re-anchored at `t`.
    fn pressure_ramp(&self, step: &StepStart<'_>) -> Ramp {
        let (t, h) = (step.t, step.h);
        let given = Ramp::read(step, vr::P);
        let ramp = if !self.extrapolate || given.slope != 0.0 {
            return given;
        } else if !self.fresh {
            self.p
        } else if self.sampled && t > self.p.t0 {
            // Two samples closer than a division resolves (a denormal step) give no slope: held.
            let slope = (given.y0 - self.p.y0) / (t - self.p.t0);
            Ramp { slope: if slope.is_finite() { slope } else { 0.0 }, ..given }
        } else {
            given
        };
        let (y, slope) = (ramp.at(t), bounded_slope(ramp.at(t), ramp.slope, h, P_RANGE));
        if slope == ramp.slope {
            ramp
        } else {
            Ramp::new(t, y, slope)
        }
    }
}

impl Model for PressureFeedbackController {
    const INFO: ModelInfo = ModelInfo {
        identifier: "PressureFeedbackController",
        description: "High-pass filtered pressure feedback for a pressure-compensated valve with counterbalance valve (thesis section 6.1)",
        log_categories: &[("logSaturation", "Spool command clamped at u_min or u_max")],
        interpolated_inputs: &[vr::U_REF, vr::P],
        documentation: DOCUMENTATION,
        terminals: &[super::terminals::CONTROLLER_VALVE, super::terminals::CONTROLLER_PRESSURE],
        ..super::plant::MODEL_INFO
    };

    const VARIABLES: &'static [Variable] = VARIABLES;
    const STATES: &'static [ContinuousState] = STATES;

    fn initialize(values: &Values) -> Result<Self, String> {
        Self::from_values(values, values.real(vr::P))
    }

    /// Re-reads the tunable parameters; keeps the filter state and the pressure samples.
    fn retune(&mut self, values: &Values) -> Result<(), String> {
        self.settings = Settings::read(values)?;
        Ok(())
    }

    fn outputs(&self, values: &mut Values) {
        let (u_comp, u) = self.command(values, self.pressure(values));
        values.set_real(vr::U_COMP, u_comp);
        values.set_real(vr::U, u.clamp(self.settings.u_min, self.settings.u_max));
        values.set_real(vr::P_LP, self.x);
    }

    fn continuous_states(&self, x: &mut [f64]) {
        x[0] = self.x;
    }

    fn set_continuous_states(&mut self, x: &[f64]) -> Result<(), String> {
        self.x = x[0];
        Ok(())
    }

    /// The filter of eq. 6.2 (Model Exchange: p is the input as set; the exact discretisation of [`HighPassFeedback::advance`] is the Co-Simulation step's).
    fn derivatives(&self, values: &Values, dx: &mut [f64]) {
        dx[0] = self.settings.feedback.state_derivative(values.real(vr::P), self.x);
    }

    fn inputs_set(&mut self, vrs: &[u32]) {
        self.fresh |= vrs.contains(&vr::P);
    }

    /// No ODE for the driver: the filter steps in closed form (below).
    type Ode = ();
    const CLOSED_FORM: bool = true;

    /// FMI 3.0 intermediate update: the command and the pressure at the step's end, each linear
    /// over the step, as FMI 2.0's input derivatives take them.
    const INTERMEDIATE_INPUTS: &'static [u32] = &[vr::U_REF, vr::P];

    /// The filter x' = omega_f (p - x) over the step, exact for the pressure ramped with its
    /// slope ([`HighPassFeedback::advance`]): a closed form no integrator beats.
    fn begin_step(&mut self, step: &StepStart<'_>, log: &mut dyn Log) -> Result<Step<'_, ()>, StepError> {
        let (values, t, h) = (step.values, step.t, step.h);
        let p = self.pressure_ramp(step);
        self.x = self.settings.feedback.advance(self.x, p.at(t), p.slope, h);
        (self.p, self.sampled, self.fresh, self.t) = (p, true, false, t + h);
        let (_, u) = self.command(values, p.at(self.t));
        self.settings.log_saturation(u, self.t, log);
        Ok(Step::Done)
    }

    /// The filter state, the time, the pressure ramp (t0, p, slope) and two flags (0/1).
    const HEAD: usize = 7;

    fn head(&self) -> Vec<f64> {
        let flag = |b: bool| if b { 1.0 } else { 0.0 };
        vec![self.x, self.t, self.p.t0, self.p.y0, self.p.slope, flag(self.sampled), flag(self.fresh)]
    }

    fn restore(values: &Values, head: &[f64], _state: &[f64]) -> Result<Self, String> {
        match *head {
            [x, t, t0, y0, slope, sampled, fresh]
                if head.iter().all(|v| v.is_finite()) && [sampled, fresh].iter().all(|f| *f == 0.0 || *f == 1.0) =>
            {
                let c = Self::from_values(values, x)?;
                let p = Ramp::new(t0, y0, slope);
                Ok(PressureFeedbackController { t, p, sampled: sampled == 1.0, fresh: fresh == 1.0, ..c })
            }
            _ => Err(format!(
                "expected the filter state, time, pressure ramp (t0, p, slope) and two flags (0/1), all finite; got {head:?}"
            )),
        }
    }
}
