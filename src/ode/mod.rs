//! General numerics for ordinary differential equations, apart from the physics that uses
//! them: the [`OdeSystem`] a stepper integrates and the [`DenseStep`] it returns (the step's
//! continuous extension), DOPRI5 (explicit Runge–Kutta 5(4)), Rodas5P (L-stable
//! Rosenbrock, [`Rodas5P`]) and the adiabatic integrator (slow motion plus
//! ringing carried mode by mode, [`adiabatic`]). The deployment (`crate::deploy`) owns the
//! physics, the events and the choice of method; nothing here knows of panels or hinges.

pub mod adiabatic;
pub(crate) mod integrator;
pub(crate) mod restore;
pub(crate) mod rosenbrock;

pub use integrator::{Change, DenseStep, OdeSystem, Tie};
pub use rosenbrock::Rodas5P;
