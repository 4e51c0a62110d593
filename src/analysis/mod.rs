//! Linearised stability analysis (thesis section 2.3 and 6.1).
pub mod modes;
