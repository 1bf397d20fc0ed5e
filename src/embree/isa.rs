//! Pinning the instruction set of Embree's kernels.
//!
//! Embree picks its traversal and intersection kernels by CPU (SSE2 up to AVX-512), and the
//! kernels of different widths do not round the same: a curve hit's distance, `u` and
//! normal differ in the last bits between them, so the same frame rendered on two CPU
//! generations differs (docs/farm.md has the measurements). A device pinned to one [`Isa`]
//! runs the same kernels on every CPU that has that instruction set, which is what lets
//! the crop pieces of one frame, rendered on mixed machines, assemble bit for bit.

use std::fmt;

use crate::error::{Result, invalid_arg};

/// An instruction set Embree can be pinned to: one per kernel set in Embree's builds
/// (Debian's 3.13 and the 4.x releases both carry exactly these four; Embree maps the
/// `sse4.2` it also accepts onto the SSE2 kernels, so it is not offered).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Isa {
    Sse2,
    Avx,
    Avx2,
    Avx512,
}

impl Isa {
    /// Every ISA, from the narrowest.
    pub const ALL: [Isa; 4] = [Isa::Sse2, Isa::Avx, Isa::Avx2, Isa::Avx512];

    /// The name Embree's configuration string and hairtrace's settings use.
    pub fn name(self) -> &'static str {
        match self {
            Isa::Sse2 => "sse2",
            Isa::Avx => "avx",
            Isa::Avx2 => "avx2",
            Isa::Avx512 => "avx512",
        }
    }

    /// Parses a name from [`Isa::name`]. Embree itself silently reads an unknown name as
    /// SSE2, so a misspelling must be refused here.
    pub fn named(name: &str) -> Result<Isa> {
        Isa::ALL
            .into_iter()
            .find(|isa| isa.name() == name)
            .ok_or_else(|| {
                invalid_arg!(
                    "isa = {name:?}: must be one of {}",
                    Isa::ALL.map(Isa::name).join(", ")
                )
            })
    }

    /// Whether this CPU (and the operating system, which must save the wider registers)
    /// can run the kernels: the features Embree itself requires for that kernel set.
    pub fn runs_here(self) -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            match self {
                Isa::Sse2 => true,
                Isa::Avx => has!("sse4.2") && has!("avx"),
                Isa::Avx2 => {
                    Isa::Avx.runs_here()
                        && has!("avx2")
                        && has!("fma")
                        && has!("bmi1")
                        && has!("bmi2")
                        && has!("lzcnt")
                }
                Isa::Avx512 => {
                    Isa::Avx2.runs_here()
                        && has!("avx512f")
                        && has!("avx512cd")
                        && has!("avx512dq")
                        && has!("avx512bw")
                        && has!("avx512vl")
                }
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            let _ = self;
            false
        }
    }

    /// The widest ISA this CPU runs: the kernels an unpinned device gets from Embree's
    /// builds, which carry all four.
    pub fn widest_here() -> Option<Isa> {
        Isa::widest(Isa::runs_here)
    }

    fn widest(runs: impl Fn(Isa) -> bool) -> Option<Isa> {
        Isa::ALL.into_iter().rev().find(|&isa| runs(isa))
    }

    /// Refuses an ISA this CPU cannot run, naming the widest one it can.
    pub(super) fn check_runs_here(self) -> Result<()> {
        self.check_runs(Isa::runs_here)
    }

    /// [`Isa::check_runs_here`] against a CPU described by `runs`.
    fn check_runs(self, runs: impl Fn(Isa) -> bool) -> Result<()> {
        if runs(self) {
            return Ok(());
        }
        let widest = Isa::widest(&runs);
        Err(invalid_arg!(
            "isa = {:?}: this CPU cannot run Embree's {} kernels (the widest it runs: {})",
            self.name(),
            self.name(),
            widest.map_or("none", Isa::name)
        ))
    }
}

impl fmt::Display for Isa {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_misspellings_are_refused() {
        for isa in Isa::ALL {
            assert_eq!(Isa::named(isa.name()), Ok(isa));
        }
        for bad in ["AVX2", "sse4.2", "avx512skx", ""] {
            let e = Isa::named(bad).unwrap_err().to_string();
            assert!(e.contains("sse2, avx, avx2, avx512"), "{e}");
        }
    }

    #[test]
    fn an_isa_the_cpu_lacks_is_refused_naming_what_it_runs() {
        let avx_machine = |isa: Isa| isa <= Isa::Avx;
        assert_eq!(Isa::Avx.check_runs(avx_machine), Ok(()));
        let e = Isa::Avx512.check_runs(avx_machine).unwrap_err().to_string();
        assert!(
            e.contains("cannot run Embree's avx512 kernels") && e.contains("widest it runs: avx)"),
            "{e}"
        );
    }

    #[test]
    fn a_wider_isa_needs_every_narrower_one() {
        assert!(Isa::Sse2.runs_here());
        for pair in Isa::ALL.windows(2) {
            assert!(!pair[1].runs_here() || pair[0].runs_here(), "{pair:?}");
        }
    }
}
