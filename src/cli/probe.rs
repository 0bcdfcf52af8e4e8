//! `candela probe`.
