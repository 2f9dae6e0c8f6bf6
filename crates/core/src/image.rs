//! Row-major image buffers with pixel (0, 0) at the top left.

/// A `width × height` grid of pixels stored row by row, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Image<T> {
    width: u32,
    height: u32,
    pixels: Vec<T>,
}

impl<T: Clone> Image<T> {
    /// An image filled with `value`.
    pub fn filled(width: u32, height: u32, value: T) -> Self {
        Self {
            width,
            height,
            pixels: vec![value; width as usize * height as usize],
        }
    }
}

impl<T> Image<T> {
    /// Wraps `pixels` (row-major, `width × height` of them); `None` if the count is wrong.
    pub fn from_pixels(width: u32, height: u32, pixels: Vec<T>) -> Option<Self> {
        (pixels.len() == width as usize * height as usize).then_some(Self {
            width,
            height,
            pixels,
        })
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    pub fn pixels(&self) -> &[T] {
        &self.pixels
    }

    pub fn pixels_mut(&mut self) -> &mut [T] {
        &mut self.pixels
    }

    pub fn into_pixels(self) -> Vec<T> {
        self.pixels
    }

    #[inline]
    fn index(&self, x: u32, y: u32) -> usize {
        debug_assert!(x < self.width && y < self.height);
        y as usize * self.width as usize + x as usize
    }

    /// The pixel at column `x`, row `y`.
    #[inline]
    pub fn get(&self, x: u32, y: u32) -> &T {
        &self.pixels[self.index(x, y)]
    }

    #[inline]
    pub fn set(&mut self, x: u32, y: u32, value: T) {
        let i = self.index(x, y);
        self.pixels[i] = value;
    }

    /// Applies `f` to every pixel, keeping the size.
    pub fn map<U>(&self, f: impl FnMut(&T) -> U) -> Image<U> {
        Image {
            width: self.width,
            height: self.height,
            pixels: self.pixels.iter().map(f).collect(),
        }
    }
}
