//! Fill-reducing orderings (placeholder: being written).
