//! flexcraft's test suite, one binary (`cargo test --release`). Every test asserts against an
//! independent truth: high-precision reference data, a closed-form or transcendental solution,
//! a published table (cited where used), a conservation law or a second formulation.

#![allow(clippy::needless_range_loop)]

mod support {
    pub mod spacecraft;
}

mod suite {
    pub mod adiabatic;
    pub mod any_spacecraft;
    pub mod array_files;
    pub mod beam_functions;
    pub mod cli;
    pub mod common;
    pub mod compliant_latch;
    pub mod coupled;
    pub mod coupled_limits;
    pub mod coupled_maximal;
    pub mod deploy;
    pub mod deploy_maximal;
    pub mod exact_beams;
    pub mod exact_peaks;
    pub mod export;
    pub mod flex42_numpy;
    pub mod hardening_input;
    pub mod hardening_output;
    pub mod hinge_closed_forms;
    pub mod implicit;
    pub mod independent_truths;
    pub mod memory_estimate;
    pub mod modal_properties;
    pub mod montecarlo;
    pub mod mutations;
    pub mod output_dir;
    pub mod plates;
    pub mod plots;
    pub mod reliability;
    pub mod report;
    pub mod response;
    pub mod response_loads;
    pub mod stresses;
    pub mod term_selection;
}
