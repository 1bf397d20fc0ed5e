//! The hair BSDF against an independent f64 reference (`common/`): normalisation, white
//! furnaces by quadrature and Monte Carlo, sampling weights and exactness, chi-square
//! goodness of fit, lobe geometry, and a sweep of hard cases. One test binary, so that
//! the crate is linked once.

mod common;

mod across;
mod chi2;
mod fidelity;
mod furnace;
mod huang;
mod lobes;
mod normalisation;
mod sampling;
mod sweep;
mod tangent;
