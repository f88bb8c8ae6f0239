//! `BEAM`: the geometrically exact beam (Reissner; Simo 1985; Cardona & Géradin 1988;
//! paper eqs. [5]–[11]) — the two-node element ([`two_node`]), the element of order p
//! on Gauss–Lobatto–Legendre nodes ([`beam_p`], which carries every elastic beam of a run,
//! `p = 1` included) and the rigid bar a section marked `RIGID` builds ([`rigid_bar`]).

pub mod beam_p;
mod kind;
pub mod rigid_bar;
pub mod two_node;

pub use kind::KIND;
