//! The `boomsim` command line and the generated modelDescription.xml and documentation pages.

mod cli;
mod linearize;
mod model_description;
