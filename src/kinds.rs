//! The registry of element kinds (issue 38 §0; `../shared/design/style.md`, "One kind, one
//! place"): one line per kind, `family::kind`, in the order of `grammar.md`'s reference.
//!
//! A kind has one half per stage it takes part in, each in its stage's family folder under
//! the kind's name, so that imports keep flowing down (deck → model ← elements → solver):
//! - `deck/build/kinds/<family>/<kind>.rs`: its `CARD` — the element types it reads, its
//!   documented keywords (the rows of `KEYWORDS`, hence of `grammar.md`), the parse of its
//!   card (tokens → the model's `ElementKind`, errors located) and the canonical writer of
//!   it (`write_deck`);
//! - `elements/<family>/<kind>`: its `KIND` — the element types it builds and the build
//!   (the model's element → the runtime `Box<dyn Element>`), beside the element itself.
//!
//! Each stage expands this one list into its own table ([`element_kinds`] calls back the
//! stage's macro with the list), so a new kind is its halves plus one line here; the deck
//! never names `elements` and `elements` never names `deck`. Every element kind is listed here.

/// Calls `$then! { family::kind, … }` with every registered kind.
macro_rules! element_kinds {
    ($then:ident) => {
        $then! {
            beams::beam,
            bodies::mass,
            bodies::superelement,
            contact::came,
            contact::clearance,
            forces::spring,
            forces::bushing,
            forces::rspring,
            forces::control,
            joints::hinge,
            joints::ujoint,
            joints::spherical,
            joints::rigid,
            joints::prescribed,
        }
    };
}
pub(crate) use element_kinds;
