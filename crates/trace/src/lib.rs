//! fray-trace (in progress).
