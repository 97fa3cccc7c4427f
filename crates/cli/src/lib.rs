//! janus2d-cli (being written).
