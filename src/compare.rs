//! `mecano-rs compare RUN REF` (stub until written).
/// Arguments.
#[derive(clap::Args, Debug, Clone)]
pub struct CompareArgs {}
/// Runs.
pub fn run(_a: &CompareArgs) -> u8 {
    2
}
