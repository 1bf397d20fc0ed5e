//! The hairtrace command line. Until the renderer lands, `lobes` is the main job: it
//! prints how the default (or a given) hair splits energy between its lobes. `info`
//! describes a .hair groom.

use clap::{Args, Parser, Subcommand};
use glam::Vec3;
use hairtrace::bsdf::{sigma_a_from_color, sigma_a_from_melanin};
use hairtrace::scene::{Thickness, info_report, read_hair_file};
use hairtrace::{HairBsdf, HairParams};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "hairtrace",
    version,
    about = "Physically based hair and fur rendering"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print the energy of the R, TT, TRT and residual lobes (averaged over the fiber's
    /// width) for a range of outgoing angles.
    Lobes(LobesArgs),
    /// Print a .hair groom's strand, point and segment counts, bounds and radius range.
    Info(InfoArgs),
}

#[derive(Args)]
struct InfoArgs {
    /// The .hair file.
    file: std::path::PathBuf,
    /// Read the file's thickness as a radius instead of a diameter (the default).
    #[arg(long)]
    thickness_is_radius: bool,
}

#[derive(Args)]
struct LobesArgs {
    /// Eumelanin concentration (about 0.3 blonde, 1.3 brown, 8 black).
    #[arg(long, default_value_t = 1.3)]
    eumelanin: f32,
    /// Pheomelanin concentration (red).
    #[arg(long, default_value_t = 0.0)]
    pheomelanin: f32,
    /// Take sigma_a from a reflectance colour "r,g,b" instead of melanin.
    #[arg(long, value_parser = parse_rgb, conflicts_with_all = ["eumelanin", "pheomelanin"])]
    color: Option<[f32; 3]>,
    /// Longitudinal roughness, [0.01, 1].
    #[arg(long, default_value_t = 0.3)]
    beta_m: f32,
    /// Azimuthal roughness, [0.01, 1].
    #[arg(long, default_value_t = 0.3)]
    beta_n: f32,
    /// Cuticle tilt in degrees.
    #[arg(long, default_value_t = 2.0)]
    alpha: f32,
    /// Index of refraction.
    #[arg(long, default_value_t = 1.55)]
    eta: f32,
}

fn parse_rgb(s: &str) -> Result<[f32; 3], String> {
    let v: Vec<f32> = s
        .split(',')
        .map(|x| x.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("{s:?}: {e}"))?;
    v.try_into()
        .map_err(|_| format!("{s:?}: expected three comma-separated numbers"))
}

fn lobes(args: &LobesArgs) -> hairtrace::Result<()> {
    let sigma_a = match args.color {
        Some(c) => sigma_a_from_color(c, args.beta_n)?,
        None => sigma_a_from_melanin(args.eumelanin, args.pheomelanin)?,
    };
    let params = HairParams {
        sigma_a,
        eta: args.eta,
        beta_m: args.beta_m,
        beta_n: args.beta_n,
        alpha: args.alpha,
    };
    let bsdf = HairBsdf::new(&params)?;
    println!(
        "sigma_a = ({:.4}, {:.4}, {:.4}), eta {}, beta_m {}, beta_n {}, alpha {} deg",
        sigma_a[0], sigma_a[1], sigma_a[2], params.eta, params.beta_m, params.beta_n, params.alpha
    );
    println!(
        "lobe energy (R G B), averaged over h in [-1, 1]; Mp and Np integrate to 1, so each lobe carries Ap"
    );
    println!(
        "{:>8}  {:^20}  {:^20}  {:^20}  {:^20}  {:^20}",
        "theta_o", "R", "TT", "TRT", "residual", "total"
    );
    const STEPS: usize = 1000;
    for deg in [0.0f32, 15.0, 30.0, 45.0, 60.0, 75.0, 85.0] {
        let t = deg.to_radians();
        let wo = Vec3::new(t.sin(), 0.0, t.cos());
        let mut sum = [Vec3::ZERO; 4];
        // Midpoint rule over h: the offset of a ray that hits the fiber is uniform.
        for i in 0..STEPS {
            let h = -1.0 + (2 * i + 1) as f32 / STEPS as f32;
            for (s, e) in sum.iter_mut().zip(bsdf.lobe_energies(h, wo)) {
                *s += e / STEPS as f32;
            }
        }
        let cell = |v: Vec3| format!("{:.3} {:.3} {:.3}", v.x, v.y, v.z);
        let total = sum.iter().copied().sum::<Vec3>();
        println!(
            "{:>7}°  {:^20}  {:^20}  {:^20}  {:^20}  {:^20}",
            deg,
            cell(sum[0]),
            cell(sum[1]),
            cell(sum[2]),
            cell(sum[3]),
            cell(total)
        );
    }
    Ok(())
}

fn info(args: &InfoArgs) -> hairtrace::Result<()> {
    let thickness = if args.thickness_is_radius {
        Thickness::Radius
    } else {
        Thickness::Diameter
    };
    let strands = read_hair_file(&args.file, thickness)?;
    print!("{}", info_report(&strands));
    Ok(())
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Lobes(a) => lobes(a),
        Command::Info(a) => info(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("hairtrace: {e}");
            ExitCode::FAILURE
        }
    }
}
