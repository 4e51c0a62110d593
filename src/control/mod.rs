//! Control laws: the high-pass filtered pressure feedback of thesis section 6.1.
