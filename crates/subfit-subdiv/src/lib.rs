//! subfit-subdiv (being written).
