//! [`Texture`]: a linear `f32` image (grey, grey + alpha, RGB or RGBA) with its whole mip chain,
//! made from texels in memory or loaded from a file (`load.rs`), its size and the chain's bytes
//! checked against a memory budget first.

use super::TextureError;
use super::mip::{self, MipLevel};
use fray_core::MemoryBudget;

/// The largest width or height of a texture, in texels (the largest 2D texture wgpu's
/// downlevel limits promise is far smaller; this bounds index arithmetic).
pub const MAX_SIDE: u32 = 1 << 16;

/// The channels a texture stores per texel. Lookups always return RGBA: grey is replicated
/// into R, G and B, a missing alpha reads 1.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Channels {
    /// One value: grey (or a scalar map: roughness, height).
    Grey,
    /// Grey and alpha.
    GreyAlpha,
    /// Red, green, blue.
    Rgb,
    /// Red, green, blue, alpha (straight, not premultiplied).
    Rgba,
}

impl Channels {
    /// Values per texel: 1 to 4.
    pub const fn count(self) -> usize {
        match self {
            Channels::Grey => 1,
            Channels::GreyAlpha => 2,
            Channels::Rgb => 3,
            Channels::Rgba => 4,
        }
    }

    /// Whether the last channel is alpha (never sRGB-decoded).
    pub const fn has_alpha(self) -> bool {
        matches!(self, Channels::GreyAlpha | Channels::Rgba)
    }
}

/// A texture: linear `f32` texels and the mip chain (module `mip`: area-average box filter,
/// each level `⌈w/2⌉ × ⌈h/2⌉`, down to 1 × 1). Row 0 of every level is the image's top row;
/// uv `(0, 0)` is the bottom-left corner (see [`crate::texture`] for the convention).
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    pub(crate) channels: Channels,
    pub(crate) levels: Vec<MipLevel>,
}

impl Texture {
    /// A texture of `width × height` linear RGB texels, `data` row-major from the top row
    /// (`3 · width · height` finite values), its chain checked against the default budget
    /// ([`MemoryBudget::default`]). For tests and procedural textures.
    pub fn from_rgb(width: u32, height: u32, data: Vec<f32>) -> Result<Self, TextureError> {
        Self::from_texels(width, height, Channels::Rgb, data, &MemoryBudget::default())
    }

    /// A texture of `width × height` texels of `channels` linear values each (row-major from the
    /// top row; every value finite), its whole mip chain's bytes checked against `budget`
    /// before the chain is built.
    pub fn from_texels(
        width: u32,
        height: u32,
        channels: Channels,
        data: Vec<f32>,
        budget: &MemoryBudget,
    ) -> Result<Self, TextureError> {
        check_size(None, u64::from(width), u64::from(height))?;
        let n = channels.count();
        let expected = width as usize * height as usize * n;
        if data.len() != expected {
            return Err(TextureError::Texels(format!(
                "a {width} × {height} texture of {n} channels needs {expected} values, got {}",
                data.len()
            )));
        }
        if let Some(i) = data.iter().position(|v| !v.is_finite()) {
            let texel = i / n;
            return Err(TextureError::Texels(format!(
                "texel ({}, {}) channel {} is not finite: {}",
                texel % width as usize,
                texel / width as usize,
                i % n,
                data[i]
            )));
        }
        budget
            .charge(
                format!("the {width} × {height} texture's mip chain"),
                Self::chain_bytes(width, height, channels),
            )
            .map_err(|source| TextureError::Budget { path: None, source })?;
        Ok(Self::build(width, height, channels, data))
    }

    /// The chain from a checked base level.
    pub(crate) fn build(width: u32, height: u32, channels: Channels, data: Vec<f32>) -> Self {
        let count = mip::level_count(width, height);
        let mut levels = Vec::with_capacity(count);
        levels.push(MipLevel {
            width,
            height,
            channels: channels.count(),
            data,
        });
        while levels.len() < count {
            let next = mip::downsample(&levels[levels.len() - 1]);
            levels.push(next);
        }
        Self { channels, levels }
    }

    /// The bytes of a `width × height` texture's whole chain of `channels` `f32` values, known
    /// before anything is allocated.
    pub fn chain_bytes(width: u32, height: u32, channels: Channels) -> u64 {
        mip::chain_texels(width, height).saturating_mul(4 * channels.count() as u64)
    }

    /// The base level's width in texels.
    pub fn width(&self) -> u32 {
        self.levels[0].width
    }

    /// The base level's height in texels.
    pub fn height(&self) -> u32 {
        self.levels[0].height
    }

    /// The channels stored per texel.
    pub fn channels(&self) -> Channels {
        self.channels
    }

    /// Every level, the base first, the 1 × 1 last.
    pub fn levels(&self) -> &[MipLevel] {
        &self.levels
    }

    /// Level `k`, clamped to the coarsest.
    pub fn level(&self, k: usize) -> &MipLevel {
        &self.levels[k.min(self.levels.len() - 1)]
    }

    /// The number of levels, `1 + ⌈log₂ max(width, height)⌉`.
    pub fn level_count(&self) -> usize {
        self.levels.len()
    }
}

/// Each side 1 to [`MAX_SIDE`].
pub(crate) fn check_size(
    path: Option<&std::path::Path>,
    width: u64,
    height: u64,
) -> Result<(), TextureError> {
    let ok = |s: u64| (1..=u64::from(MAX_SIDE)).contains(&s);
    if ok(width) && ok(height) {
        Ok(())
    } else {
        Err(TextureError::Size {
            path: path.map(ToOwned::to_owned),
            width,
            height,
        })
    }
}
