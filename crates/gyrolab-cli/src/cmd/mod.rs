//! One module per subcommand; none imports another (what they share lives beside `cmd`).

pub mod allan;
pub mod apply;
pub mod batch;
pub mod bias;
pub mod convert;
pub mod demo;
pub mod eval;
pub mod inspect;
pub mod rate;
pub mod record_length;
pub mod simulate;
pub mod store;
pub mod verify;
