//! fray-scene (in progress).
