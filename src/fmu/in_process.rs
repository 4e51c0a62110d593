//! An FMU instance driven in-process through the FMI layer ([`Instance`], what the exported
//! symbols call), as an importer drives it through the C ABI: for `boomsim bench` and the
//! documentation's figures.

use super::instance::{Instance, Step};
use super::log::Logger;
use super::state::Interface;
use super::variables::BaseType;
use super::{guid::guid, Model, Value};

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
        let log = Logger::new(None, "bench", &[], false);
        let mut i = Instance::<M>::new(log, guid::<M>(), crate::fmu::Version::Fmi2, Interface::CoSimulation);
        i.setup_experiment(Some(rtol), 0.0, None)?;
        i.enter_initialization_mode();
        for (r, x) in start {
            i.set(&[*r], vec![x.clone()])?;
        }
        i.exit_initialization_mode()?;
        Ok(InProcess(i))
    }
}

impl<M: Model> Slave for InProcess<M> {
    fn set(&mut self, vr: u32, x: f64) -> Result<(), String> {
        self.0.set(&[vr], vec![Value::Real(x)])
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
