//! Integration tests of `trilux-tests`: one binary, one module a topic.

mod adapters;
mod cross;
mod stuffing;
