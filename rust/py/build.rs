//! Records the cargo profile this extension is built with (`librate.build_info()["profile"]`):
//! cargo tells build scripts only "debug" or "release" (PROFILE), so the name is read from the
//! output directory, <target>/[<triple>/]<profile dir>/build/<package>-<hash>/out, where the
//! profile directory is "debug" for `dev` and the profile's own name otherwise.

fn main() {
    let out = std::env::var("OUT_DIR").unwrap_or_default();
    let dir = std::path::Path::new(&out).ancestors().nth(3).and_then(|p| p.file_name()).and_then(|n| n.to_str()).unwrap_or("unknown");
    let profile = if dir == "debug" { "dev" } else { dir };
    println!("cargo:rustc-env=LIBRATE_PROFILE={profile}");
    println!("cargo:rerun-if-changed=build.rs");
}
