//! The work behind the subcommands, shared by them (cargo's
//! `commands/*` → `ops::*`): each subcommand module parses its arguments
//! into a job and calls these; no subcommand module imports another.

pub(crate) mod colors;
pub(crate) mod object;
pub(crate) mod plot;
pub(crate) mod sample;
pub(crate) mod stuff;
