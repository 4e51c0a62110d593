//! Control laws: the high-pass filtered pressure feedback of thesis section 6.1.

pub mod pressure_feedback;

pub use pressure_feedback::{HighPassFeedback, FEEDBACK_PARAMS};
