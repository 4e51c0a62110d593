//! The C ABI in-process: both versions' state machines and misuse catalogues, Model Exchange, directional derivatives, the declared dependencies, what hostile hosts found.

#[path = "../common/mod.rs"]
mod common;
mod clocks;
mod dependencies;
mod enumerations;
mod early_return;
mod directional_derivatives;
mod fmi2_api;
mod fmi3_api;
mod hardening;
mod intermediate_update;
mod lookahead;
mod outputs;
mod misuse;
mod model_exchange;
