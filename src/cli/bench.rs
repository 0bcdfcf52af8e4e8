//! `candela bench`.
