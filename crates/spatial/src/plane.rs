//! Plane grid boxes (placeholder, being written).
