//! The library's Embree major version as `cfg(embree3)` / `cfg(embree4)` (the groom bench
//! calls Embree directly, whose calls differ between the two), and its folder as an rpath
//! where the library's build script found Embree outside the loader's paths.

fn main() {
    println!("cargo::rerun-if-env-changed=DEP_EMBREE_MAJOR");
    println!("cargo::rerun-if-env-changed=DEP_EMBREE_RPATH");
    println!("cargo::rustc-check-cfg=cfg(embree3)");
    println!("cargo::rustc-check-cfg=cfg(embree4)");
    if let Ok(major) = std::env::var("DEP_EMBREE_MAJOR") {
        println!("cargo::rustc-cfg=embree{major}");
    }
    if let Ok(dir) = std::env::var("DEP_EMBREE_RPATH") {
        println!("cargo::rustc-link-arg=-Wl,-rpath,{dir}");
    }
}
