//! Link-only crate: see `build.rs`. It exports nothing.
