//! One spelling per name of a choice (see [`crate::named_choice`]).

/// A choice with one name per value: what [`crate::named_choice`] gives an enum, so that
/// generic code (a command line's parser and help) can list every name.
pub trait NamedChoice: Sized + 'static {
    /// Every value, in the order they are listed.
    fn all() -> &'static [Self];
    /// The value's one spelling.
    fn choice_name(&self) -> &'static str;
}

/// Implements `Display` and `FromStr` for a choice (an enum with an `ALL` array and a
/// `name()`), so that each name has one spelling, which a command line, a lab's matrix, a
/// script and a UI all share: after `named_choice!(Quality, "quality");`, `"high"` parses
/// and `"ultra"` is refused with an error listing the quality names.
#[macro_export]
macro_rules! named_choice {
    ($type:ty, $what:literal) => {
        impl $crate::NamedChoice for $type {
            fn all() -> &'static [Self] {
                &Self::ALL
            }

            fn choice_name(&self) -> &'static str {
                self.name()
            }
        }

        impl ::std::fmt::Display for $type {
            fn fmt(&self, f: &mut ::std::fmt::Formatter<'_>) -> ::std::fmt::Result {
                f.write_str(self.name())
            }
        }

        impl ::std::str::FromStr for $type {
            type Err = String;

            fn from_str(text: &str) -> Result<Self, String> {
                Self::ALL
                    .into_iter()
                    .find(|choice| choice.name() == text)
                    .ok_or_else(|| {
                        let names: Vec<&str> = Self::ALL.iter().map(|c| c.name()).collect();
                        format!(
                            "unknown {} `{text}`: expected one of {}",
                            $what,
                            names.join(", ")
                        )
                    })
            }
        }
    };
}

impl NamedChoice for manylights_scene::Shading {
    fn all() -> &'static [Self] {
        &Self::ALL
    }

    fn choice_name(&self) -> &'static str {
        self.name()
    }
}
