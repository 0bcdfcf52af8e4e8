//! `candela luminaire`.
