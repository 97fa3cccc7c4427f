//! janus2d-render (being written).
