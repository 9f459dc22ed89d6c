//! Placeholder: the step format layer is being written.
