//! End-to-end tests of the stuffing pipeline on code-built shapes.
