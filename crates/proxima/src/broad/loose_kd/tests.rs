//! Unit tests of the loose k-d tree (the oracle suite lives in `tests/oracle`).
