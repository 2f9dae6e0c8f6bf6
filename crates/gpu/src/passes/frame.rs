//! A scene's frame as an ordered list of passes: ray generation, the intersection pass of each
//! kind it has (`crate::kinds::KINDS`, in their order), shade, Whitted's queue passes where its
//! materials reflect or transmit, the media where it has a medium, resolve — built once per
//! resident scene from its features.

use super::{PassSetup, band, media, raygen, resolve, shade, whitted};
use crate::GpuError;
use crate::features::{Feature, Features};

/// The band passes of a scene with `features`, in frame order, before and after Whitted's
/// queue passes (which follow shade when it has `Feature::Whitted`): ray generation; the
/// intersection pass of each kind it has (`crate::kinds::KINDS`, in their order); shade; then
/// the media (with a fog layer, a sky or clouds) and resolve.
pub fn frame_specs(features: Features) -> (Vec<band::PassSpec>, Vec<band::PassSpec>) {
    let mut before = vec![raygen::RAYGEN];
    for kind in crate::kinds::KINDS {
        if features.has_kind(kind.kind()) {
            before.push(kind.intersection());
        }
    }
    before.push(shade::SHADE);
    let mut after = Vec::new();
    if features.media() {
        after.push(media::MEDIA);
    }
    after.push(resolve::RESOLVE);
    (before, after)
}

/// A scene's frame: its passes in order ([`frame_specs`], Whitted's between shade and the media),
/// as its specialisation calls for them, built once when the scene is uploaded.
pub fn frame_passes(setup: &PassSetup<'_>) -> Result<Vec<Box<dyn band::Pass>>, GpuError> {
    let features = setup.specialisation.features;
    let (before, after) = frame_specs(features);
    let mut passes: Vec<Box<dyn band::Pass>> = Vec::new();
    for spec in before {
        passes.push(Box::new(band::BandPass::new(setup, spec)?));
    }
    if features.has(Feature::Whitted) {
        passes.push(Box::new(whitted::WhittedPasses::new(
            setup,
            features.media(),
        )?));
    }
    for spec in after {
        passes.push(Box::new(band::BandPass::new(setup, spec)?));
    }
    Ok(passes)
}

#[cfg(test)]
mod tests {
    use crate::features::{Feature, Features};
    use crate::shader::{self, ModuleOptions};
    use fray_scene::PrimitiveKind;

    /// Every set of features (each kind, medium, Whitted's rays, textures on or off).
    fn every_set() -> impl Iterator<Item = Features> {
        let all: Vec<Feature> = Feature::all().collect();
        (0..1u32 << all.len()).map(move |k| {
            all.iter().enumerate().fold(Features::NONE, |set, (i, f)| {
                set.with_if(*f, k & (1 << i) != 0)
            })
        })
    }

    /// Every pass binds its groups in the order its module numbers them (so a pipeline layout
    /// has no gaps and a bind group lands at the index the WGSL declares), for every composition.
    #[test]
    fn every_pass_binds_the_groups_its_module_declares_in_order() {
        for features in every_set() {
            let options = ModuleOptions {
                features,
                ..ModuleOptions::default()
            };
            let (before, after) = super::frame_specs(features);
            let mut specs: Vec<_> = before.into_iter().chain(after).collect();
            if features.has(Feature::Whitted) {
                use crate::passes::whitted::{
                    FORWARD, GATHER, INTERSECT, SELECT_LEVEL, SELECT_PARENTS,
                };
                specs.extend([FORWARD, INTERSECT, SELECT_PARENTS, GATHER, SELECT_LEVEL]);
            }
            for spec in specs {
                let declared = shader::module_groups(spec.entry, &options).unwrap();
                let groups: Vec<_> = spec.groups(&options).into_iter().map(|(_, g)| g).collect();
                assert_eq!(declared, groups, "{} ({options:?})", spec.entry);
            }
        }
        let declared = shader::module_groups("rebase.wgsl", &ModuleOptions::BATCH).unwrap();
        assert_eq!(declared, [crate::bindings::REBASE]);
    }

    /// The frame holds exactly the passes the scene's features call for, in order.
    #[test]
    fn the_frame_follows_the_features() {
        let labels = |features| {
            let (before, after) = super::frame_specs(features);
            before
                .iter()
                .chain(&after)
                .map(|s| s.label)
                .collect::<Vec<_>>()
        };
        let free_forms = Features::NONE.with(Feature::Kind(PrimitiveKind::FreeForm));
        assert_eq!(
            labels(free_forms),
            ["raygen", "free forms", "shade", "resolve"]
        );
        let all = Features::NONE
            .with(Feature::Kind(PrimitiveKind::Mesh))
            .with(Feature::Kind(PrimitiveKind::Terrain))
            .with(Feature::Fog);
        assert_eq!(
            labels(all),
            ["raygen", "terrains", "meshes", "shade", "media", "resolve"]
        );
    }
}
