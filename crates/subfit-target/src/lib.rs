//! subfit-target (being written).
