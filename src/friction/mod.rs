//! The stick-slip transition model of Peng, Roch, Bonn & Weber (PRL 134, 176202, 2025).
//!
//! Each contact pixel is an element of normal force n_i = p_i · a; it stays stuck while its
//! shear is below mu_s · n_i and carries mu_d · n_i once slipped. The tangential load is
//! shared equally by the stuck elements and the excess a slipping element releases is
//! redistributed over them (a fibre bundle with equal load sharing). From a pressure map
//! and a [`FrictionLaw`] this module computes the [`Onset`] of sliding (static friction,
//! friction drop, critical / pre-sliding / subcritical elements, their maps) and the
//! friction–displacement [`Curve`]. [`elastic_onset`] replaces equal sharing by the elastic
//! interaction of the contact points through the half-space (the tangential solve);
//! [`spring_slider_onset`] keeps equal sharing but gives it the same slip weakening.
//!
//! Must not import study, shs, plot or report: friction builds on contact and the base row.

mod curve;
mod elastic;
mod law;
mod onset;
mod slide_class;
mod slip_law;
mod spring_slider;
mod stiffness;

pub use curve::{displacement, write_curves_csv, Curve, CurvePoint, Loading};
pub use elastic::{
    check_partial_slip_force, check_peak_tolerance, elastic_onset, ramp_force, ElasticOnset, SlidePoint,
    SlideProgress, SlideStage, SlideWork, Snapshot, PEAK_TOLERANCE,
};
pub use law::{check_curve_unit, law_from_curve, parse_curve, slip_curve_file, CurveError, FrictionLaw, PRESETS};
pub use onset::{ClassShare, ElementClass, ElementLoads, Onset};
pub use slide_class::{SlideClass, SlideClasses};
pub use slip_law::{SlipLaw, Weakening, DEFAULT_SLIP_DISTANCE_M};
pub use spring_slider::{spring_slider_onset, WeakeningOnset};
pub use stiffness::{element_stiffness, stuck_stiffness};
