//! `candela falsecolour`.
