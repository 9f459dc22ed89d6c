//! Placeholder: the iges format layer is being written.
