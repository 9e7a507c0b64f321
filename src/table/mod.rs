//! Precomputed tables of the configuration space (thesis 3.2.4-3.2.6; SPEC §6).
