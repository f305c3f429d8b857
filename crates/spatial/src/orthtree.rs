//! Orthtree (placeholder, being written).
