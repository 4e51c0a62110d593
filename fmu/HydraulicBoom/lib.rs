//! The HydraulicBoom FMU: exports the FMI 2.0 and FMI 3.0 C ABI for the model.
#![allow(non_snake_case)]
boomsim::export_fmu!(boomsim::models::HydraulicBoom);
