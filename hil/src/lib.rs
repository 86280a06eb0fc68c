//! Hardware in the loop without the hardware: serial links behind a port trait, pseudo-terminal
//! pairs, and firmware in the loop (the robot command port).
//!
//! The links arrive with their issues (#4, #8); until then this crate holds no code.
#![warn(missing_docs)]
