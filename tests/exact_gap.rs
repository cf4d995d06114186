//! (to be written: list scheduler vs exact optimum on random small DAGs)
