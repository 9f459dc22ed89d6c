//! The command-line front end (being written).

/// Entry point of the `nurbsx` binary.
pub fn main() -> std::process::ExitCode {
    eprintln!("nurbsx: commands are being written");
    std::process::ExitCode::from(2)
}
