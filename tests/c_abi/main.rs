//! The C ABI as a C or C++ host meets it: the generated header matches the sources, and the
//! example programs compile as C99 and C++ with warnings as errors, link the static
//! archive and run; the BSDF entry points refuse bad arguments and give the Rust bits.

mod bsdf_c;
mod c_examples;
mod header;
mod memcheck;
mod motion_cpp;
mod quiet;
mod sections;
