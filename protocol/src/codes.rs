//! [`code_enum!`]: a code ↔ enum mapping written once, as one table; both directions (and, for
//! a closed set, the list of every value) are generated from it.

/// Declares an enum whose variants stand for codes on the wire, from one table.
///
/// `pub enum Name (to_code, from_code): Type { Variant = code, … }` gives `Name::to_code(self)`
/// and `Name::from_code(Type) -> Option<Name>`, and `Name::ALL`, every variant in table order.
/// With `unknown Other` after the table, the enum also gets `Other(Type)`, which keeps any code
/// the table does not name, and `from_code` returns `Name` (every code decodes).
macro_rules! code_enum {
    (
        $(#[$meta:meta])*
        pub enum $name:ident ($to:ident, $from:ident): $ty:ty {
            $( $(#[$vmeta:meta])* $variant:ident = $code:literal, )+
        }
    ) => {
        $(#[$meta])*
        pub enum $name {
            $( $(#[$vmeta])* $variant, )+
        }

        impl $name {
            /// Every value, in the table's order.
            pub const ALL: [$name; [$($name::$variant),+].len()] = [$($name::$variant),+];

            /// Its code on the wire.
            #[must_use]
            pub const fn $to(self) -> $ty {
                match self {
                    $( $name::$variant => $code, )+
                }
            }

            /// The value whose code is `code`, if the table names it.
            #[must_use]
            pub const fn $from(code: $ty) -> Option<Self> {
                match code {
                    $( $code => Some($name::$variant), )+
                    _ => None,
                }
            }
        }
    };
    (
        $(#[$meta:meta])*
        pub enum $name:ident ($to:ident, $from:ident): $ty:ty {
            $( $(#[$vmeta:meta])* $variant:ident = $code:literal, )+
        }
        $(#[$umeta:meta])* unknown $unknown:ident
    ) => {
        $(#[$meta])*
        pub enum $name {
            $( $(#[$vmeta])* $variant, )+
            $(#[$umeta])*
            $unknown($ty),
        }

        impl $name {
            /// Its code on the wire.
            #[must_use]
            pub const fn $to(self) -> $ty {
                match self {
                    $( $name::$variant => $code, )+
                    $name::$unknown(code) => code,
                }
            }

            /// The value of `code` (a code the table does not name is kept as it is).
            #[must_use]
            pub const fn $from(code: $ty) -> Self {
                match code {
                    $( $code => $name::$variant, )+
                    other => $name::$unknown(other),
                }
            }
        }
    };
}

pub(crate) use code_enum;
