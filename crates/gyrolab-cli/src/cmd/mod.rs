//! One module per subcommand.

pub mod apply;
pub mod bias;
pub mod demo;
pub mod rate;
pub mod raw;
pub mod simulate;
