//! Empty: the package holds only its benchmarks (see Cargo.toml).
