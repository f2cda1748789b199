//! Result file and summary (in progress).
