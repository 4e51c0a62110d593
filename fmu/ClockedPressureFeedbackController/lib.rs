//! The ClockedPressureFeedbackController FMU: exports the C ABI for the model (FMI 3.0 Model
//! Exchange; its FMI 2.0 symbols refuse to instantiate it).
#![allow(non_snake_case)]
boomsim::export_fmu!(boomsim::models::ClockedPressureFeedbackController);
