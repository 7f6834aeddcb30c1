//! Output (placeholder: being written).
