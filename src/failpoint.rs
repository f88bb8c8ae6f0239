//! The failure-injection hook `MECANO_FAILPOINT` (issue 27 §1c): the tests of interruption and
//! restart stop a run at a known step (`signal:NAME:STEP`, see `app::session`) or kill it in
//! the middle of a checkpoint's write (`checkpoint:N`, see [`crate::checkpoint`]).
//!
//! A hook that can SIGKILL a run must not be reachable in a release binary by an environment
//! variable alone, so it is compiled only into builds with debug assertions (cargo's `dev` and
//! `test` profiles: the binary that `cargo test` builds for the integration tests, whatever
//! its `opt-level`) or with the cargo feature `failpoints` (to run those tests against an
//! optimised build: `cargo test --release --features failpoints`). In any other build
//! (`cargo build --release`, `cargo install`) [`var`] is `None` whatever the environment says.
//! Debug assertions rather than a feature alone because the README's one test command,
//! `cargo test`, must run the restart tests: a feature would have to be named on it, and
//! `required-features` would skip those tests silently without it.

/// Whether the hook is compiled into this build.
pub const ENABLED: bool = cfg!(any(debug_assertions, feature = "failpoints"));

/// The value of `MECANO_FAILPOINT` when the hook is compiled in, `None` otherwise.
pub fn var() -> Option<String> {
    if ENABLED {
        std::env::var("MECANO_FAILPOINT").ok()
    } else {
        None
    }
}
