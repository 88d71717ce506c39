//! Reference trajectories: continuous-time motion models sampled into truth records.
