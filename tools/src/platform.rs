//! The platforms an .fmu carries binaries for, and how each is built: the host (Linux x86-64)
//! with the project's toolchain, Windows x64 and Linux aarch64 with Debian's `rustc-web` /
//! `cargo-web` 1.96 and `rust-web-src`, which build the standard library for the target
//! (`-Zbuild-std`, accepted by that stable compiler with `RUSTC_BOOTSTRAP=1`) and link with
//! MinGW-w64 and aarch64 GCC (`scripts/setup-cross` installs them, all from apt).

use boomsim::fmu::Version;
use std::path::{Path, PathBuf};
use std::process::Command;

/// One binary platform of an FMU.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Platform {
    /// The folder under `binaries/` in FMI 2.0 (section 2.1; fmpy's name for aarch64 Linux),
    /// and the platform's name on the command line.
    pub name: &'static str,
    /// The folder under `binaries/` in FMI 3.0: the platform tuple (FMI 3.0, 2.5.1.1).
    pub tuple: &'static str,
    /// Rust target triple; `None`: the host.
    pub target: Option<&'static str>,
    /// The linker's prefix of a cdylib's file name (`lib` on Linux) and the library suffix.
    pub prefix: &'static str,
    pub suffix: &'static str,
    /// The cross linker (Debian package in `scripts/setup-cross`).
    pub linker: &'static str,
}

/// Every platform boomsim ships, the host first.
pub const PLATFORMS: [Platform; 3] = [
    Platform { name: "linux64", tuple: "x86_64-linux", target: None, prefix: "lib", suffix: ".so", linker: "" },
    Platform {
        name: "win64",
        tuple: "x86_64-windows",
        target: Some("x86_64-pc-windows-gnu"),
        prefix: "",
        suffix: ".dll",
        linker: "x86_64-w64-mingw32-gcc",
    },
    Platform {
        name: "aarch64-linux",
        tuple: "aarch64-linux",
        target: Some("aarch64-unknown-linux-gnu"),
        prefix: "lib",
        suffix: ".so",
        linker: "aarch64-linux-gnu-gcc",
    },
];

/// Debian's toolchain for the cross builds (packages `rustc-web`, `cargo-web`).
const CROSS_CARGO: &str = "/usr/bin/cargo";
const CROSS_RUSTC: &str = "/usr/bin/rustc";

impl Platform {
    /// The platforms named in a comma-separated list (`all`: every one).
    pub fn parse_list(list: &str) -> Result<Vec<Platform>, String> {
        if list == "all" {
            return Ok(PLATFORMS.to_vec());
        }
        list.split(',')
            .map(|n| {
                PLATFORMS.iter().copied().find(|p| p.name == n.trim()).ok_or_else(|| {
                    let names: Vec<_> = PLATFORMS.iter().map(|p| p.name).collect();
                    format!("unknown platform \"{n}\"; the platforms are {} (or all)", names.join(", "))
                })
            })
            .collect()
    }

    /// The folder under `binaries/` in FMI `version`.
    pub fn folder(&self, version: Version) -> &'static str {
        match version {
            Version::Fmi2 => self.name,
            Version::Fmi3 => self.tuple,
        }
    }

    /// The binary's path inside the .fmu of FMI `version` for model `id`.
    pub fn entry(&self, version: Version, id: &str) -> String {
        format!("binaries/{}/{id}{}", self.folder(version), self.suffix)
    }

    /// Where the build of this platform leaves the library of `id` under the target dir `target`.
    pub fn library(&self, target: &Path, id: &str) -> PathBuf {
        let dir = match self.target {
            None => target.join("release"),
            Some(t) => target.join("cross").join(t).join("release"),
        };
        dir.join(format!("{}{id}{}", self.prefix, self.suffix))
    }

    /// The cargo command that builds `packages` for this platform in release mode from the
    /// workspace `root` into the target dir `target` (cross builds in `target/cross`, so that the
    /// two toolchains never share build artefacts).
    pub fn build_command(&self, root: &Path, target: &Path, packages: &[&str]) -> Result<Command, String> {
        let cargo = match self.target {
            None => std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()),
            Some(_) => CROSS_CARGO.into(),
        };
        let mut c = Command::new(cargo);
        c.current_dir(root).args(["build", "--release", "--quiet"]);
        if let Some(t) = self.target {
            if let Some(tool) = [CROSS_CARGO, CROSS_RUSTC, self.linker].into_iter().find(|t| !installed(t)) {
                return Err(format!("{tool} is missing for {}: run scripts/setup-cross", self.name));
            }
            let linker = format!("CARGO_TARGET_{}_LINKER", t.to_uppercase().replace('-', "_"));
            c.env("RUSTC", CROSS_RUSTC).env("RUSTC_BOOTSTRAP", "1").env(linker, self.linker);
            c.args(["-Zbuild-std=std,panic_unwind", "--target", t]).arg("--target-dir").arg(target.join("cross"));
        }
        for p in packages {
            c.args(["-p", p]);
        }
        Ok(c)
    }
}

/// Whether a tool exists: an absolute path, or a name on PATH.
fn installed(tool: &str) -> bool {
    let on_path = || std::env::var_os("PATH").is_some_and(|p| std::env::split_paths(&p).any(|d| d.join(tool).is_file()));
    Path::new(tool).is_file() || on_path()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn platform_lists() {
        assert_eq!(Platform::parse_list("all").unwrap(), PLATFORMS.to_vec());
        let p = Platform::parse_list("linux64,win64").unwrap();
        assert_eq!(p.iter().map(|p| p.name).collect::<Vec<_>>(), ["linux64", "win64"]);
        assert!(Platform::parse_list("darwin64").unwrap_err().contains("linux64, win64, aarch64-linux"));
        assert_eq!(PLATFORMS[1].entry(Version::Fmi2, "X"), "binaries/win64/X.dll");
        assert_eq!(PLATFORMS[1].entry(Version::Fmi3, "X"), "binaries/x86_64-windows/X.dll");
        assert_eq!(PLATFORMS[0].entry(Version::Fmi3, "X"), "binaries/x86_64-linux/X.so");
        let lib = PLATFORMS[2].library(Path::new("t"), "X");
        assert_eq!(lib, Path::new("t/cross/aarch64-unknown-linux-gnu/release/libX.so"));
    }
}
