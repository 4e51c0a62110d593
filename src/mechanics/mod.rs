//! Boom kinematics, kinetics and deflection (thesis section 2.1).
