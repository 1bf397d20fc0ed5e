//! Records as an rpath the Embree folder that the library's build script found outside the
//! loader's paths (scripts/embree4's), so that the command line and its tests run without
//! LD_LIBRARY_PATH, as the library's own binaries do.

fn main() {
    println!("cargo::rerun-if-env-changed=DEP_EMBREE_RPATH");
    if let Ok(dir) = std::env::var("DEP_EMBREE_RPATH") {
        println!("cargo::rustc-link-arg=-Wl,-rpath,{dir}");
    }
}
