//! `candela render` and `candela merge`.
