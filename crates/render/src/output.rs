//! Writing frames as PNG (sRGB, 8/16-bit) and EXR (linear float with depth).
