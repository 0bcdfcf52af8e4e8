//! `candela spectrum` and `candela convert`.
