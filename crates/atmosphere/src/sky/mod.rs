//! A physically based sky: Rayleigh and Mie single scattering (and ozone absorption) over a
//! spherical Earth, its f64 numerical integral, and precomputed tables for speed.
//!
//! - [`SkyModel`]: the planet and its atmosphere (Bruneton 2017 / Hillaire 2020's Earth);
//!   [`SkySun`]: the sun's direction, irradiance and disc; [`phase`]: the phase functions.
//! - [`reference`](mod@reference): optical depth and single scattering by adaptive
//!   quadrature, the accuracy reference (no tables).
//! - [`Sky`]: the model, the sun and the [`TransmittanceTable`] (built once); [`Sky::view`]
//!   builds a [`SkyViewTable`] for one observer (once a frame) into a [`SkyView`], whose
//!   [`SkyView::background`] is the radiance of a camera ray that hits nothing;
//!   [`Sky::aerial_perspective`] is the in-scatter and transmittance in front of a surface.
//!
//! **The observer-centred frame.** World space is Y up, in metres. The sky is evaluated with the
//! planet's centre straight below the observer: the eye is at `(0, r_eye, 0)` from the centre,
//! `r_eye = ground_radius + (eye.y − ground_elevation)`, and a point `eye + t·dir` is at
//! `(0, r_eye, 0) + t·dir`. So the sky does not depend on the horizontal position (a camera far
//! from the origin sees the same sky), and "up" is `+Y` at the eye. An eye below the ground
//! (`eye.y < ground_elevation`, or a NaN height) is put on the ground; one higher than
//! [`MAX_OBSERVER_ALTITUDE`] at that altitude. Above the top of the atmosphere rays enter the
//! shell later or never.
//!
//! What is left out: multiple scattering, the ground's reflected light (the planet's surface
//! is black: the scene brings its own ground), refraction, limb darkening, the moon and stars.
//! `docs/sky.md` has the parameterisations for a GPU twin and the measured errors.
//!
//! ```
//! use fray_atmosphere::sky::{Sky, SkyModel, SkySun, SkyTables};
//! use fray_core::MemoryBudget;
//! use glam::DVec3;
//!
//! let sun = SkySun::from_angles(30f64.to_radians(), 0.0, DVec3::splat(1.0));
//! let tables = SkyTables { transmittance_width: 64, transmittance_height: 16,
//!                          sky_view_width: 32, sky_view_height: 24, ..SkyTables::default() };
//! let sky = Sky::new(SkyModel::earth(), sun, tables, &MemoryBudget::default())?;
//! let view = sky.view(DVec3::new(0.0, 2.0, 0.0));
//! let zenith = view.background(DVec3::Y);
//! assert!(zenith.z > zenith.y && zenith.y > zenith.x); // blue
//! # Ok::<(), fray_atmosphere::AtmosphereError>(())
//! ```

mod geometry;
mod march;
mod model;
pub mod phase;
pub mod reference;
mod sky_view_table;
mod sun;
mod texels;
mod transmittance_table;

pub use model::{MAX_OBSERVER_ALTITUDE, SkyModel};
pub use sky_view_table::SkyViewTable;
pub use sun::SkySun;
pub use transmittance_table::TransmittanceTable;

use crate::AtmosphereError;
use fray_core::MemoryBudget;
use geometry::Planet;
use glam::DVec3;
use march::Marcher;
use std::sync::Arc;

/// The largest table side (texels).
pub const MAX_TABLE_SIDE: u32 = 4096;

/// The most steps [`Sky::aerial_perspective`] and the sky-view table take along one ray.
pub const MAX_STEPS: u32 = 4096;

/// The most march steps one sky-view table may take to fill (texels × steps per texel): a
/// table is filled for every new eye height, so every frame of a climb. The default table
/// (192 × 108 × 40 = 829 440 steps) took 135 ms on 2 threads (`docs/sky.md`); the cap, 20× it,
/// about 2.7 s. Without it 4096² texels × 4096 steps would take hours.
pub const MAX_SKY_VIEW_MARCH_STEPS: u64 = 1 << 24;

/// Light added along a path and the path's transmittance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScatterTerms {
    /// Radiance scattered toward the eye along the path (W/(m² sr), RGB).
    pub in_scatter: DVec3,
    /// Transmittance of the path (RGB): what reaches the eye of the light from its far end.
    pub transmittance: DVec3,
}

impl ScatterTerms {
    /// An empty path: nothing added, everything transmitted.
    pub const EMPTY: Self = Self {
        in_scatter: DVec3::ZERO,
        transmittance: DVec3::ONE,
    };

    /// What the eye sees of `radiance` leaving the path's far end: `T · radiance + in-scatter`.
    pub fn apply(&self, radiance: DVec3) -> DVec3 {
        self.transmittance * radiance + self.in_scatter
    }
}

/// The sizes of the sky's tables and the sky-view table's steps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SkyTables {
    /// Transmittance table texels along `μ` (default 256).
    pub transmittance_width: u32,
    /// Transmittance table texels along `r` (default 64).
    pub transmittance_height: u32,
    /// Sky-view table texels along the azimuth (default 192).
    pub sky_view_width: u32,
    /// Sky-view table texels along the zenith angle (default 108; even).
    pub sky_view_height: u32,
    /// Steps of the sky-view table's march per texel (default 40).
    pub sky_view_steps: u32,
}

impl Default for SkyTables {
    fn default() -> Self {
        Self {
            transmittance_width: TransmittanceTable::DEFAULT_WIDTH,
            transmittance_height: TransmittanceTable::DEFAULT_HEIGHT,
            sky_view_width: SkyViewTable::DEFAULT_WIDTH,
            sky_view_height: SkyViewTable::DEFAULT_HEIGHT,
            sky_view_steps: 40,
        }
    }
}

impl SkyTables {
    /// Checks the sizes: every side in `2..=4096`, the sky-view height even and at least 4, the
    /// steps in `1..=4096`, the sky-view table's march within [`MAX_SKY_VIEW_MARCH_STEPS`].
    pub fn validate(&self) -> Result<(), AtmosphereError> {
        use transmittance_table::check_side;
        check_side("sky.tables.transmittance_width", self.transmittance_width)?;
        check_side("sky.tables.transmittance_height", self.transmittance_height)?;
        check_side("sky.tables.sky_view_width", self.sky_view_width)?;
        check_side("sky.tables.sky_view_height", self.sky_view_height)?;
        AtmosphereError::check(
            "sky.tables.sky_view_height",
            f64::from(self.sky_view_height),
            self.sky_view_height >= 4 && self.sky_view_height.is_multiple_of(2),
            "must be even and at least 4 (the horizon lies between its two halves)",
        )?;
        AtmosphereError::check(
            "sky.tables.sky_view_steps",
            f64::from(self.sky_view_steps),
            (1..=MAX_STEPS).contains(&self.sky_view_steps),
            "must lie in 1..=4096",
        )?;
        let march_steps = u64::from(self.sky_view_width)
            * u64::from(self.sky_view_height)
            * u64::from(self.sky_view_steps);
        if march_steps > MAX_SKY_VIEW_MARCH_STEPS {
            return Err(AtmosphereError::Work {
                field: "sky.tables.sky_view_steps",
                what: format!(
                    "a {} × {} sky-view table of {} steps per texel",
                    self.sky_view_width, self.sky_view_height, self.sky_view_steps
                ),
                work: march_steps,
                limit: MAX_SKY_VIEW_MARCH_STEPS,
            });
        }
        Ok(())
    }
}

/// The sky for one model and sun, with its transmittance table.
#[derive(Clone, Debug)]
pub struct Sky {
    model: SkyModel,
    sun: SkySun,
    tables: SkyTables,
    transmittance: Arc<TransmittanceTable>,
}

impl Sky {
    /// Validates `model`, `sun` (its direction is normalised) and `tables`, checks both tables'
    /// sizes against `budget`, and builds the transmittance table.
    pub fn new(
        model: SkyModel,
        sun: SkySun,
        tables: SkyTables,
        budget: &MemoryBudget,
    ) -> Result<Self, AtmosphereError> {
        model.validate()?;
        let sun = checked_sun(sun)?;
        tables.validate()?;
        // The sky-view table of every later `view` has this size (one lives while the scene
        // renders): charge it now.
        budget.charge_elements(
            "the sky-view table",
            u64::from(tables.sky_view_width) * u64::from(tables.sky_view_height),
            std::mem::size_of::<[f32; 4]>() as u64,
        )?;
        let transmittance = TransmittanceTable::new(
            &model,
            tables.transmittance_width,
            tables.transmittance_height,
            budget,
        )?;
        Ok(Self {
            model,
            sun,
            tables,
            transmittance: Arc::new(transmittance),
        })
    }

    /// The model.
    pub fn model(&self) -> &SkyModel {
        &self.model
    }

    /// The sun (direction normalised).
    pub fn sun(&self) -> &SkySun {
        &self.sun
    }

    /// The table sizes.
    pub fn tables(&self) -> &SkyTables {
        &self.tables
    }

    /// The transmittance table (for upload).
    pub fn transmittance_table(&self) -> &TransmittanceTable {
        &self.transmittance
    }

    /// Moves the sun (validated; the transmittance table does not depend on it).
    pub fn set_sun(&mut self, sun: SkySun) -> Result<(), AtmosphereError> {
        self.sun = checked_sun(sun)?;
        Ok(())
    }

    fn marcher(&self) -> Marcher<'_> {
        Marcher {
            model: &self.model,
            table: &self.transmittance,
            toward_sun: self.sun.direction,
            irradiance: self.sun.irradiance,
        }
    }

    /// Builds the sky-view table for an observer at `eye` (only `eye.y` matters; see the
    /// frame in the module docs): what a frame builds once.
    pub fn view(&self, eye: DVec3) -> SkyView {
        let r = self.model.observer_radius(eye.y);
        let table = SkyViewTable::build(
            &self.marcher(),
            r,
            self.tables.sky_view_width,
            self.tables.sky_view_height,
            self.tables.sky_view_steps,
        );
        SkyView {
            model: self.model,
            sun: self.sun,
            eye,
            transmittance: Arc::clone(&self.transmittance),
            table,
        }
    }

    /// In-scatter and transmittance over `[0, t]` of the ray `eye + s·dir` that meets a surface
    /// at distance `t` (aerial perspective), marched in `steps` steps (clamped to `1..=4096`)
    /// with the transmittance table for the sun. The path is clipped to the atmosphere and
    /// stopped on the planet's ground; `t = ∞` marches the whole sky ray; `t ≤ 0`, a NaN `t` or
    /// a zero direction is an empty path. The surface's radiance `L` is seen as
    /// [`ScatterTerms::apply`]`(L)`.
    pub fn aerial_perspective(&self, eye: DVec3, dir: DVec3, t: f64, steps: u32) -> ScatterTerms {
        let Some(d) = dir.try_normalize() else {
            return ScatterTerms::EMPTY;
        };
        let r = self.model.observer_radius(eye.y);
        let planet = Planet::of(&self.model);
        match planet.segment(r, d.y.clamp(-1.0, 1.0), t, true) {
            Some(segment) => self
                .marcher()
                .march(r, d, segment, steps.clamp(1, MAX_STEPS)),
            None => ScatterTerms::EMPTY,
        }
    }

    /// Transmittance of sunlight from the top of the atmosphere to the world point `p` (the
    /// observer at `eye` fixes the planet's centre), from the table; 0 where the planet is in
    /// the way (the sun below the point's horizon). Multiply the sun's irradiance by it to dim
    /// direct sunlight on a surface.
    pub fn transmittance_to_sun(&self, p: DVec3, eye: DVec3) -> DVec3 {
        let (r, mu) = reference::point_radius_and_cosine(&self.model, p, eye, self.sun.direction);
        self.transmittance.lookup(r, mu)
    }

    /// The sun's irradiance reaching the world point `p` (on a surface facing the sun):
    /// `E · transmittance_to_sun(p, eye)`.
    pub fn sun_irradiance_at(&self, p: DVec3, eye: DVec3) -> DVec3 {
        self.sun.irradiance * self.transmittance_to_sun(p, eye)
    }
}

/// `sun` validated, its direction normalised.
fn checked_sun(sun: SkySun) -> Result<SkySun, AtmosphereError> {
    sun.validate()?;
    Ok(SkySun {
        direction: sun.unit_direction(),
        ..sun
    })
}

/// The sky seen from one observer: its sky-view table and the sun's disc.
#[derive(Clone, Debug)]
pub struct SkyView {
    model: SkyModel,
    sun: SkySun,
    eye: DVec3,
    transmittance: Arc<TransmittanceTable>,
    table: SkyViewTable,
}

impl SkyView {
    /// The eye the view was built for.
    pub fn eye(&self) -> DVec3 {
        self.eye
    }

    /// The observer's planet-centred radius (clamped; see the module docs).
    pub fn observer_radius(&self) -> f64 {
        self.table.observer_radius()
    }

    /// The sky-view table (for upload).
    pub fn table(&self) -> &SkyViewTable {
        &self.table
    }

    /// The sun (direction normalised).
    pub fn sun(&self) -> &SkySun {
        &self.sun
    }

    /// The sky's in-scattered radiance along `dir`, from the table (no sun disc).
    pub fn lookup(&self, dir: DVec3) -> DVec3 {
        self.table.lookup(dir)
    }

    /// The radiance of a camera ray along `dir` that hits nothing: the table's sky plus the
    /// sun's disc seen through the view transmittance (hidden below the horizon). A zero
    /// direction looks up.
    pub fn background(&self, dir: DVec3) -> DVec3 {
        self.table.lookup(dir) + self.sun_disc(dir)
    }

    /// The sun's disc alone along `dir`: `E/Ω · T_view(dir)` inside the disc, 0 outside.
    pub fn sun_disc(&self, dir: DVec3) -> DVec3 {
        let d = dir.try_normalize().unwrap_or(DVec3::Y);
        if self.sun.in_disc(d) {
            self.sun.disc_radiance() * self.transmittance(d)
        } else {
            DVec3::ZERO
        }
    }

    /// The disc's radiance at the eye toward the sun's centre, `E/Ω · T_view(sun)`.
    pub fn sun_radiance_at_eye(&self) -> DVec3 {
        self.sun.disc_radiance() * self.sun_transmittance_at_eye()
    }

    /// The transmittance from the eye toward the sun's centre (0 below the horizon); the
    /// sun's irradiance at the eye is `E` times it.
    pub fn sun_transmittance_at_eye(&self) -> DVec3 {
        self.transmittance(self.sun.direction)
    }

    /// Transmittance from the eye along `dir` out of the atmosphere (from the table; 1 for a
    /// ray that misses the shell, 0 for one that meets the ground). A zero direction looks up.
    pub fn transmittance(&self, dir: DVec3) -> DVec3 {
        let d = dir.try_normalize().unwrap_or(DVec3::Y);
        let planet = Planet::of(&self.model);
        let r = self.table.observer_radius();
        let mu = d.y.clamp(-1.0, 1.0);
        if planet.hits_ground(r, mu) {
            return DVec3::ZERO;
        }
        if r <= planet.top {
            return self.transmittance.lookup(r, mu);
        }
        // From above: the table's ray starts where this one enters the shell.
        match planet.segment(r, mu, f64::INFINITY, true) {
            Some(s) => {
                let mu_entry = ((r * mu + s.t0) / planet.top).clamp(-1.0, 1.0);
                self.transmittance.lookup(planet.top, mu_entry)
            }
            None => DVec3::ONE,
        }
    }
}
