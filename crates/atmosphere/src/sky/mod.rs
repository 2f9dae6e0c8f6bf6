//! A physically based sky: Rayleigh and Mie single scattering (and ozone absorption) over a
//! spherical Earth, its f64 numerical integral, and precomputed tables for speed.
