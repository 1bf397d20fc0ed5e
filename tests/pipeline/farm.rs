//! Farm renders across mixed CPUs: Embree's kernels for different instruction sets give
//! different bits, so crop pieces rendered on different machines assemble into the full
//! frame bit for bit only when every piece pins the same ISA. A "machine" here is a device
//! whose Embree sees no ISA wider than the machine's (`max_isa`), which is what a CPU
//! without those instructions looks like to Embree.

use hairtrace::description::{self, SceneDescription};
use hairtrace::embree::{Device, Isa};
use hairtrace::render::{Aovs, NoProgress};
use std::path::Path;
use std::sync::Arc;

const W: u32 = 48;
const H: u32 = 36;

fn scene() -> SceneDescription {
    let mut d = description::demo("furball").unwrap();
    (d.render.width, d.render.height, d.render.spp) = (W, H, 2);
    d
}

/// Renders rows `y0..y1` on `machine`, with Embree pinned to `pin` when given.
fn render_rows(machine: Isa, pin: Option<Isa>, y0: u32, y1: u32) -> Vec<u32> {
    let config = format!(
        "max_isa={machine},{}",
        Device::config(Some(1), pin).unwrap()
    );
    let device = Arc::new(Device::with_config(&config).unwrap());
    let mut d = scene();
    d.render.crop = Some([0, y0, W, y1]);
    let mut built = d.build(device).unwrap();
    let out = built.render(Aovs::default(), &NoProgress).unwrap();
    out.film.rgb().iter().map(|v| v.to_bits()).collect()
}

/// One band of rows per machine, stacked: the assembled frame.
fn assemble(machines: &[Isa], pin: Option<Isa>) -> Vec<u32> {
    let n = machines.len() as u32;
    let mut frame = Vec::new();
    for (i, &machine) in machines.iter().enumerate() {
        let i = i as u32;
        frame.extend(render_rows(machine, pin, H * i / n, H * (i + 1) / n));
    }
    frame
}

#[test]
fn pieces_from_mixed_isas_assemble_bit_for_bit_only_when_pinned() {
    let machines: Vec<Isa> = Isa::ALL.into_iter().filter(|i| i.runs_here()).collect();
    if machines.len() < 2 {
        eprintln!("only {machines:?} runs here: no mixed machines to stand in for");
        return;
    }
    let widest = *machines.last().unwrap();
    // Unpinned, each machine runs its widest kernels: the assembled frame is neither
    // machine's full frame (the finding that makes pinning necessary).
    let mixed = assemble(&machines, None);
    for machine in [Isa::Sse2, widest] {
        assert_ne!(
            mixed,
            render_rows(machine, None, 0, H),
            "unpinned pieces matched {machine}'s full frame: pinning would be untested"
        );
    }
    // Pinned to SSE2 (every x86-64 CPU runs it), any mix of machines gives the frame the
    // widest machine renders alone with the same pin.
    let pinned = assemble(&machines, Some(Isa::Sse2));
    assert_eq!(pinned, render_rows(widest, Some(Isa::Sse2), 0, H));
    // And the pin reaches Embree: the pinned frame is not the widest machine's own.
    assert_ne!(pinned, render_rows(widest, None, 0, H));
}

#[test]
fn the_scene_file_pins_the_isa_and_refuses_unknown_names() {
    let parse = |text: &str| SceneDescription::from_toml(text, Path::new("."), "test.toml");
    let d = parse("[render]\nisa = \"sse2\"\n").unwrap();
    assert_eq!(d.render.isa, Some(hairtrace::embree::Isa::Sse2));
    assert!(d.render.device().is_ok());
    let bad = parse("[render]\nisa = \"avx3\"\n").unwrap_err().to_string();
    assert!(
        bad.contains("test.toml:2:1: render.isa = avx3: must be sse2 | avx | avx2 | avx512"),
        "{bad}"
    );
}
