//! Parameter values that are words of a fixed set (`abi=plain|robotran`): the [`Word`] trait
//! and the `word_enum!` macro that declares such an enum once, words and all.

/// A parameter value that is one word of a fixed set (`abi=plain|robotran`), as declared by
/// `word_enum!` (below).
pub trait Word: Copy + 'static {
    /// Every word, in the order of the variants: the choices of the parameter's declaration.
    const WORDS: &'static [&'static str];
    /// The value's word, as written in a pipeline and in the report.
    fn as_str(self) -> &'static str;
    /// The value written `word`, if any.
    fn from_word(word: &str) -> Option<Self>;
}

/// Declares an enum whose values are the words of a parameter: each variant is written
/// `Variant = "word"`. The enum gets `WORDS` (every word, in variant order: what the
/// parameter's [`crate::params::ParamKind::Choice`] declares as `choices`), `const fn as_str`, `from_word`,
/// [`crate::params::Word`] (for [`crate::Params::word`]), and `Serialize` as its word (the report writes `"robotran"`).
#[macro_export]
macro_rules! word_enum {
    (
        $(#[$meta:meta])*
        pub enum $name:ident {
            $($(#[$vmeta:meta])* $variant:ident = $word:literal,)+
        }
    ) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq)]
        pub enum $name {
            $($(#[$vmeta])* $variant,)+
        }

        impl $name {
            /// Every word, in the variants' order: the parameter's choices.
            pub const WORDS: &'static [&'static str] = &[$($word),+];

            /// The value's word, as written in a pipeline and in the report.
            pub const fn as_str(self) -> &'static str {
                match self {
                    $($name::$variant => $word,)+
                }
            }

            /// The value written `word`, if any.
            pub fn from_word(word: &str) -> Option<$name> {
                match word {
                    $($word => Some($name::$variant),)+
                    _ => None,
                }
            }
        }

        impl $crate::params::Word for $name {
            const WORDS: &'static [&'static str] = $name::WORDS;

            fn as_str(self) -> &'static str {
                $name::as_str(self)
            }

            fn from_word(word: &str) -> Option<$name> {
                $name::from_word(word)
            }
        }

        impl serde::Serialize for $name {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.serialize_str(self.as_str())
            }
        }
    };
}
pub use crate::word_enum;

/// `codegen<fpga;resources=…>` reads its words from the machine's `Logic`, which holds them
/// (implemented here: the trait is this crate's, the type the machine's).
impl Word for robovec_machine::resources::Logic {
    const WORDS: &'static [&'static str] = robovec_machine::resources::Logic::WORDS;

    fn as_str(self) -> &'static str {
        robovec_machine::resources::Logic::as_str(self)
    }

    fn from_word(word: &str) -> Option<robovec_machine::resources::Logic> {
        robovec_machine::resources::Logic::from_word(word)
    }
}

/// `codegen<fpga;interconnect=…>` reads its words from the machine's `Interconnect`.
impl Word for robovec_machine::design::routes::Interconnect {
    const WORDS: &'static [&'static str] = robovec_machine::design::routes::Interconnect::WORDS;

    fn as_str(self) -> &'static str {
        robovec_machine::design::routes::Interconnect::as_str(self)
    }

    fn from_word(word: &str) -> Option<robovec_machine::design::routes::Interconnect> {
        robovec_machine::design::routes::Interconnect::from_word(word)
    }
}
