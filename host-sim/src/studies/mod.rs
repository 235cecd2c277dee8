//! Studies that regenerate pages of `docs/`: regime sweeps ([`sweep`]), the criterion against
//! simulation on random machines ([`criterion`]), the run-up capture page ([`runup`]), and what
//! accuracy costs ([`accuracy`], [`cost`], [`publish`]).

pub mod accuracy;
pub mod cost;
pub mod criterion;
pub mod publish;
pub mod runup;
pub mod sweep;
