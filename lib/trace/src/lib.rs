//! The reference ray tracer.
