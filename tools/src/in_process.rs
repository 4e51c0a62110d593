//! An FMU instance driven in-process through the FMI layer ([`Instance`], what the exported
//! symbols call), as an importer drives it through the C ABI: for `boomsim bench` and the
//! documentation's figures.

use boomsim::fmu::guid::token;
use boomsim::fmu::instance::{Instance, Step};
use boomsim::fmu::log::Logger;
use boomsim::fmu::machine::{Interface, Mode};
use boomsim::fmu::model::clock_row;
use boomsim::fmu::variables::BaseType;
use boomsim::fmu::Version;
use boomsim::fmu::{guid::guid, Model, Value};

/// One co-simulation slave, however it is reached.
pub trait Slave {
    fn set(&mut self, vr: u32, x: f64) -> Result<(), String>;
    fn get(&mut self, vr: u32) -> Result<f64, String>;
    fn step(&mut self, t: f64, h: f64) -> Result<(), String>;
}

/// A slave called in-process through the generic FMI layer.
pub struct InProcess<M: Model>(Instance<M>);

impl<M: Model> InProcess<M> {
    /// Instantiated, set up with `rtol`, initialised with the given Real and Boolean values.
    pub fn new(rtol: f64, start: &[(u32, Value)]) -> Result<Self, String> {
        let mut s = Self::initializing(Some(rtol), 0.0, None, start)?;
        s.exit_initialization_mode()?;
        Ok(s)
    }

    /// Instantiated, set up for `[t0, stop]` with `rtol` (None: the model's default), in
    /// Initialization Mode with the `start` values set.
    pub fn initializing(rtol: Option<f64>, t0: f64, stop: Option<f64>, start: &[(u32, Value)]) -> Result<Self, String> {
        let log = Logger::new(None, M::INFO.identifier, &[], false);
        let mut i = Instance::<M>::new(log, guid::<M>(), boomsim::fmu::Version::Fmi2, Interface::CoSimulation);
        i.setup_experiment(rtol, t0, stop)?;
        i.enter_initialization_mode();
        for (r, x) in start {
            i.set(&[*r], x.base_type(), vec![x.clone()])?;
        }
        Ok(InProcess(i))
    }

    /// Leaves Initialization Mode.
    pub fn exit_initialization_mode(&mut self) -> Result<(), String> {
        self.0.exit_initialization_mode()
    }

    /// A model with a Clock (FMI 3.0 Model Exchange), set up for `[0, stop]`, in Initialization
    /// Mode.
    pub fn clocked(stop: f64) -> Result<Self, String> {
        let log = Logger::new(None, M::INFO.identifier, &[], false);
        let mut i = Instance::<M>::new(log, token::<M>(), Version::Fmi3, Interface::ModelExchange);
        i.setup_experiment(None, 0.0, Some(stop))?;
        i.enter_initialization_mode();
        Ok(InProcess(i))
    }

    /// A clocked instance's activation of its Clock at `t`, as an importer's time event: from
    /// the Event Mode that initialisation ends in, that instant ended and Continuous-Time Mode;
    /// then the time set, Event Mode, the Clock set, the clocked inputs set by `inputs`, the
    /// outputs read by `outputs`, fmi3UpdateDiscreteStates, Continuous-Time Mode.
    pub fn tick<T>(
        &mut self,
        t: f64,
        inputs: impl FnOnce(&mut Self) -> Result<(), String>,
        outputs: impl FnOnce(&mut Self) -> Result<T, String>,
    ) -> Result<T, String> {
        let clock = clock_row::<M>().map(|i| M::VARIABLES[i].vr).ok_or("the model has no Clock")?;
        if self.0.core.mode == Mode::EventMode {
            self.0.update_discrete_states()?;
            self.0.core.mode = Mode::ContinuousTimeMode;
        }
        self.0.set_time(t)?;
        self.0.core.mode = Mode::EventMode;
        self.0.set_clocks(&[clock], &[true])?;
        inputs(self)?;
        let read = outputs(self)?;
        self.0.update_discrete_states()?;
        self.0.core.mode = Mode::ContinuousTimeMode;
        Ok(read)
    }

    /// The slope of Real input `vr` over the next step (fmi2SetRealInputDerivatives, order 1).
    pub fn set_slope(&mut self, vr: u32, slope: f64) -> Result<(), String> {
        self.0.set_input_derivatives(&[vr], &[1], &[slope])
    }
}

impl<M: Model> Slave for InProcess<M> {
    fn set(&mut self, vr: u32, x: f64) -> Result<(), String> {
        self.0.set(&[vr], BaseType::Real, vec![Value::Real(x)])
    }
    fn get(&mut self, vr: u32) -> Result<f64, String> {
        let mut x = [0.0];
        self.0.get(&[vr], &mut x, BaseType::Real, |v| if let Value::Real(x) = v { *x } else { f64::NAN })?;
        Ok(x[0])
    }
    fn step(&mut self, t: f64, h: f64) -> Result<(), String> {
        match self.0.do_step(t, h)? {
            Step::Done(_) => Ok(()),
            Step::Discarded(why) => Err(why),
        }
    }
}
