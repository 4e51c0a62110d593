//! The ClockedPressureFeedbackController FMU model (FMI 3.0, Model Exchange): the feedback of
//! thesis section 6.1 as the rig runs it, a sampled controller. Its input Clock `sample` has a
//! constant 5 ms interval (the real-time controller's loop period, thesis 4.2.2) and its first
//! activation 5 ms after the start; at each activation the controller samples `p` and `u_ref`,
//! advances its filter over the interval and sets the command `u`, which holds until the next
//! one. The FMU has no continuous state: coupled with the plant in Model Exchange, the importer
//! integrates the plant and activates the Clock as a time event (FMI 3.0, 2.2.8); in
//! Co-Simulation (with Event Mode, which a Clock requires) it steps to each activation and
//! activates the Clock in Event Mode.
//!
//! Discretisation of eq. 6.2 (a choice: the thesis gives the filter in continuous time): the
//! filter x' = omega_f (p - x) is advanced exactly over the interval T with p linear between the
//! last two samples ([`HighPassFeedback::advance`]),
//!
//! ```text
//! x_k = advance(x_k-1, p_k-1, (p_k - p_k-1) / T, T),   u_k = clamp(u_ref_k + K_f omega_f (p_k - x_k) / Q_rated)
//! ```
//!
//! which is what the continuous controller computes when a master steps it by T with the slope
//! of p over the step (`scripts/rig_loop.py`'s 5 ms runs), so both give the same commands for the
//! same samples. The clocked states are `filter.p_lp` (x) and `filter.p_sample` (p_k-1), each with
//! its previous value. At the start the filter rests at the initial p (u = u_ref).

use super::pressure_feedback_controller::{row, vr, Settings};
use crate::fmu::driver::Step;
use crate::fmu::{ContinuousState, Log, Model, ModelInfo, StepError, StepStart, Values, Variable};

/// The Clock's interval [s]: the rig's loop period (thesis 4.2.2: the real-time controller's
/// cycle times start at 5 ms).
pub const INTERVAL: f64 = 5e-3;

const VARIABLES: &[Variable] = &[
    row::U_REF.clocked(),
    row::P.clocked(),
    // FMI 3.0, 2.4.8: the dependencies of a clocked variable list its Clock too, and the
    // discrete-time states its partition starts from (the filter's x and p sample).
    row::U.clocked().depends(&[vr::U_REF, vr::P, vr::SAMPLE, vr::P_LP, vr::P_SAMPLE]).initial_depends(&[vr::U_REF]),
    row::U_COMP.clocked().depends(&[vr::P, vr::SAMPLE, vr::P_LP, vr::P_SAMPLE]).initial_depends(&[]),
    row::K_F,
    row::OMEGA_F,
    row::Q_RATED,
    row::ENABLE,
    row::U_MIN,
    row::U_MAX,
    row::P_LP.clocked().previous(vr::P_LP_PREVIOUS),
    Variable::clock(
        "sample",
        vr::SAMPLE,
        (INTERVAL, INTERVAL),
        "The controller's sampling: every 5 ms from 5 ms after the start (the rig's loop period, thesis 4.2.2)",
    ),
    Variable::real_local(
        "filter.p_sample",
        vr::P_SAMPLE,
        "Pa",
        "bar",
        "The fed-back pressure sampled at the last activation",
    )
    .clocked()
    .previous(vr::P_SAMPLE_PREVIOUS),
    Variable::real_local(
        "filter.p_lp_previous",
        vr::P_LP_PREVIOUS,
        "Pa",
        "bar",
        "filter.p_lp at the activation before",
    )
    .clocked(),
    Variable::real_local(
        "filter.p_sample_previous",
        vr::P_SAMPLE_PREVIOUS,
        "Pa",
        "bar",
        "filter.p_sample at the activation before",
    )
    .clocked(),
];

const DOCUMENTATION: &str = r#"<p>The high-pass filtered pressure feedback of thesis section 6.1 (eq. 6.2) as a
sampled controller, the way the rig runs it (section 4.2.2: a 5 ms loop). Its input Clock <code>sample</code> is
periodic with the constant interval T = 5 ms, first 5 ms after the start. At each activation (fmi3SetClock in Event
Mode) the controller samples <i>p</i> and <i>u</i><sub>ref</sub>, advances the filter x' = &omega;<sub>f</sub>(p
&minus; x) exactly over T with <i>p</i> linear between the last two samples, and sets u = clamp(u<sub>ref</sub> +
K<sub>f</sub>&omega;<sub>f</sub>(p &minus; x)/Q<sub>rated</sub>, u<sub>min</sub>, u<sub>max</sub>), held until the
next activation: the command the continuous PressureFeedbackController gives when stepped by 5 ms with the slope of
<i>p</i>. Couple it with HydraulicBoom in Model Exchange: integrate the plant, and at each multiple of 5 ms enter
Event Mode, activate <code>sample</code>, set <i>p</i> = p4 and <i>u</i><sub>ref</sub>, read <i>u</i>, call
fmi3UpdateDiscreteStates and pass <i>u</i> to the plant. In Co-Simulation (instantiated with eventModeUsed, which a
Clock requires) step to each activation and activate the Clock in Event Mode (fmi3EnterEventMode, fmi3SetClock, the
inputs, the outputs, fmi3UpdateDiscreteStates, fmi3EnterStepMode); a step past an activation is refused. Each
activation is made once: a skipped or repeated one is refused with fmi3Error (FMI 3.0, 2.2.8.2). Clocked
variables can be set and read only while the Clock is active (and in Initialization Mode). FMI 3.0 only.</p>"#;

/// The sampled controller: its parameters and its clocked states (this activation's and the
/// previous ones).
#[derive(Debug, Clone, PartialEq)]
pub struct ClockedPressureFeedbackController {
    settings: Settings,
    /// Filter state x and pressure sample of this activation (between activations, the last).
    x: f64,
    p_sample: f64,
    /// The same at the activation before ([`Model::update_previous`] moves them on).
    x_previous: f64,
    p_sample_previous: f64,
    /// u_comp and the unclamped u of the last activation (at the start: 0 and u_ref).
    u_comp: f64,
    u: f64,
}

impl Model for ClockedPressureFeedbackController {
    const INFO: ModelInfo = ModelInfo {
        identifier: "ClockedPressureFeedbackController",
        description: "High-pass filtered pressure feedback (thesis section 6.1) sampled every 5 ms by an FMI 3.0 \
                      Clock, as the rig runs it",
        log_categories: &[("logSaturation", "Spool command clamped at u_min or u_max")],
        documentation: DOCUMENTATION,
        ..super::plant::MODEL_INFO
    };

    const VARIABLES: &'static [Variable] = VARIABLES;
    const STATES: &'static [ContinuousState] = &[];

    /// At rest at the initial pressure: x = p, u_comp = 0.
    fn initialize(values: &Values) -> Result<Self, String> {
        let p = values.real(vr::P);
        Ok(ClockedPressureFeedbackController {
            settings: Settings::read(values)?,
            x: p,
            p_sample: p,
            x_previous: p,
            p_sample_previous: p,
            u_comp: 0.0,
            u: values.real(vr::U_REF),
        })
    }

    fn retune(&mut self, values: &Values) -> Result<(), String> {
        self.settings = Settings::read(values)?;
        Ok(())
    }

    fn outputs(&self, values: &mut Values) {
        values.set_real(vr::U_COMP, self.u_comp);
        values.set_real(vr::U, self.u.clamp(self.settings.u_min, self.settings.u_max));
        values.set_real(vr::P_LP, self.x);
        values.set_real(vr::P_SAMPLE, self.p_sample);
        values.set_real(vr::P_LP_PREVIOUS, self.x_previous);
        values.set_real(vr::P_SAMPLE_PREVIOUS, self.p_sample_previous);
    }

    fn continuous_states(&self, _x: &mut [f64]) {}

    fn set_continuous_states(&mut self, _x: &[f64]) -> Result<(), String> {
        Ok(())
    }

    fn derivatives(&self, _values: &Values, _dx: &mut [f64]) {}

    /// The filter over the interval from the previous sample to this one (module doc), and the
    /// command from this sample.
    fn evaluate_partition(&mut self, values: &Values) {
        let (p, feedback) = (values.real(vr::P), &self.settings.feedback);
        let slope = (p - self.p_sample_previous) / INTERVAL;
        self.x = feedback.advance(self.x_previous, self.p_sample_previous, slope, INTERVAL);
        self.p_sample = p;
        (self.u_comp, self.u) = self.settings.command(values.real(vr::U_REF), p, self.x);
    }

    fn update_previous(&mut self) {
        (self.x_previous, self.p_sample_previous) = (self.x, self.p_sample);
    }

    /// Co-Simulation (with Event Mode): between activations nothing changes, the command holds.
    type Ode = ();
    const CLOSED_FORM: bool = true;

    fn begin_step(&mut self, _step: &StepStart<'_>, _log: &mut dyn Log) -> Result<Step<'_, ()>, StepError> {
        Ok(Step::Done)
    }

    /// The clocked states, their previous values and the last command.
    const HEAD: usize = 6;

    fn head(&self) -> Vec<f64> {
        vec![self.x, self.p_sample, self.x_previous, self.p_sample_previous, self.u_comp, self.u]
    }

    fn restore(values: &Values, head: &[f64], _state: &[f64]) -> Result<Self, String> {
        match *head {
            [x, p_sample, x_previous, p_sample_previous, u_comp, u] if head.iter().all(|v| v.is_finite()) => {
                let settings = Settings::read(values)?;
                Ok(ClockedPressureFeedbackController {
                    settings,
                    x,
                    p_sample,
                    x_previous,
                    p_sample_previous,
                    u_comp,
                    u,
                })
            }
            _ => Err(format!(
                "expected the filter state and pressure sample, their previous values and the last u_comp and u, \
                 all finite; got {head:?}"
            )),
        }
    }
}
