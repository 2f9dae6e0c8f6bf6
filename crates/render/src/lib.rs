//! fray-render (in progress).
