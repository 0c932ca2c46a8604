//! What the options sections of the planners and of plan execution share: the error of an
//! invalid value ([`OptionsError`], re-exported as `planners::OptionsError`) and a serde helper.
//!
//! It sits below both (`exec`, `planners::settings` and the planner modules import it), so none
//! of them has to import another for it.

/// A field that is present must hold a value (`null` is refused, as for the full type).
///
/// # Errors
/// The value's own.
pub(crate) fn present<'de, D: serde::Deserializer<'de>, T: serde::Deserialize<'de>>(
    d: D,
) -> Result<Option<T>, D::Error> {
    T::deserialize(d).map(Some)
}

/// An invalid option value.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{field}: {message}")]
pub struct OptionsError {
    /// The option, as `section.field` once the section is known.
    pub field: String,
    /// What is wrong.
    pub message: String,
}

impl OptionsError {
    /// An error about `field`.
    pub fn new(field: &str, message: impl Into<String>) -> Self {
        Self {
            field: field.to_string(),
            message: message.into(),
        }
    }

    /// Prefixes the field with its options section (`ba_star.tile_side_m`).
    #[must_use]
    pub fn in_section(mut self, section: &str) -> Self {
        if !self.field.is_empty() && !self.field.starts_with(section) {
            self.field = format!("{section}.{}", self.field);
        }
        self
    }
}
