//! Isosurface stuffing (Labelle & Shewchuk 2007) with generalized winding numbers.
