//! GPU structs from one definition: [`gpu_struct!`](crate::gpu_struct) declares a
//! `#[repr(C)]` bytemuck struct *and* its WGSL twin from the same field list, so the two cannot
//! disagree on the order or the types of their fields; [`GpuStruct::check_layout`] proves that
//! WGSL's alignment rules put every field at the offset Rust does (a field type WGSL pads
//! differently, such as a 3-vector, fails it).
//!
//! ```
//! fray_core::gpu_struct! {
//!     /// A light as the GPU reads it.
//!     pub struct Light {
//!         pub position: [f32; 4],
//!         pub kind: u32,
//!         pub flags: u32,
//!         pub pad: [u32; 2],
//!     }
//! }
//! use fray_core::gpu_struct::GpuStruct;
//! assert_eq!(
//!     Light::declaration(),
//!     "struct Light {\n    position: vec4<f32>,\n    kind: u32,\n    flags: u32,\n    pad: vec2<u32>,\n}\n"
//! );
//! Light::check_layout().unwrap();
//! ```

/// A Rust type that has a WGSL counterpart with the same size (host-shareable, storage layout).
pub trait WgslType: bytemuck::Pod {
    /// Its alignment in WGSL's storage layout.
    const ALIGN: usize;
    /// Its size in WGSL's storage layout.
    const SIZE: usize;
    /// The WGSL type, e.g. `vec4<f32>`.
    fn wgsl() -> String;
}

macro_rules! wgsl_scalar {
    ($($rust:ty => $wgsl:literal, $align:literal, $size:literal;)*) => {
        $(impl WgslType for $rust {
            const ALIGN: usize = $align;
            const SIZE: usize = $size;
            fn wgsl() -> String {
                $wgsl.to_owned()
            }
        })*
    };
}

/// Fixed arrays of 4-vectors: WGSL `array<vec4<…>, N>` (stride 16, as in Rust).
macro_rules! wgsl_vec4_array {
    ($($element:ty => $wgsl:literal;)*) => {
        $(impl<const N: usize> WgslType for [$element; N]
        where
            [$element; N]: bytemuck::Pod,
        {
            const ALIGN: usize = 16;
            const SIZE: usize = 16 * N;
            fn wgsl() -> String {
                format!("array<{}, {N}>", $wgsl)
            }
        })*
    };
}

wgsl_vec4_array! {
    [f32; 4] => "vec4<f32>";
    [u32; 4] => "vec4<u32>";
}

wgsl_scalar! {
    f32 => "f32", 4, 4;
    u32 => "u32", 4, 4;
    i32 => "i32", 4, 4;
    [f32; 2] => "vec2<f32>", 8, 8;
    [u32; 2] => "vec2<u32>", 8, 8;
    [f32; 4] => "vec4<f32>", 16, 16;
    [u32; 4] => "vec4<u32>", 16, 16;
    [i32; 4] => "vec4<i32>", 16, 16;
}

/// One field of a [`GpuStruct`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WgslField {
    pub name: &'static str,
    /// The WGSL type.
    pub ty: String,
    /// Where Rust puts it (`offset_of!`).
    pub rust_offset: usize,
    pub wgsl_align: usize,
    pub wgsl_size: usize,
}

/// A struct declared by [`gpu_struct!`](crate::gpu_struct): its WGSL declaration and layout.
pub trait GpuStruct: WgslType {
    /// The fields in declaration order.
    fn fields() -> Vec<WgslField>;

    /// The WGSL declaration, e.g. `struct Light {\n    position: vec4<f32>,\n}\n`.
    fn declaration() -> String {
        let mut s = format!("struct {} {{\n", Self::wgsl());
        for f in Self::fields() {
            s.push_str(&format!("    {}: {},\n", f.name, f.ty));
        }
        s.push_str("}\n");
        s
    }

    /// Each field's offset and the struct's size under WGSL's storage-layout rules (a field
    /// starts at the next multiple of its alignment; the size rounds up to the largest one).
    fn wgsl_layout() -> (Vec<usize>, usize) {
        let mut offset = 0usize;
        let mut align = 1usize;
        let mut offsets = Vec::new();
        for f in Self::fields() {
            offset = offset.next_multiple_of(f.wgsl_align);
            offsets.push(offset);
            offset += f.wgsl_size;
            align = align.max(f.wgsl_align);
        }
        (offsets, offset.next_multiple_of(align))
    }

    /// `Ok` when WGSL lays every field out where Rust does and the sizes agree; else which field
    /// (or the size) differs.
    fn check_layout() -> Result<(), String> {
        let (offsets, size) = Self::wgsl_layout();
        for (f, wgsl) in Self::fields().iter().zip(&offsets) {
            if f.rust_offset != *wgsl {
                return Err(format!(
                    "{}.{}: Rust offset {}, WGSL offset {wgsl}",
                    Self::wgsl(),
                    f.name,
                    f.rust_offset
                ));
            }
        }
        let rust = std::mem::size_of::<Self>();
        if rust != size || Self::SIZE != size {
            return Err(format!(
                "{}: Rust size {rust}, WGSL size {size}",
                Self::wgsl()
            ));
        }
        Ok(())
    }
}

/// Declares a `#[repr(C)]`, `Pod` struct and its WGSL twin ([`GpuStruct`]) from one field list.
/// Field types must implement [`WgslType`]: `f32`, `u32`, `i32`, `[f32; 2|4]`, `[u32; 2|4]`,
/// `[i32; 4]`, arrays of 4-vectors `[[f32; 4]; N]`, `[[u32; 4]; N]`, or another `gpu_struct!`
/// (3-vectors are left out on purpose: WGSL pads them).
/// The calling crate needs `bytemuck` (with `derive`) as a dependency.
#[macro_export]
macro_rules! gpu_struct {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident {
            $($(#[$field_meta:meta])* $field_vis:vis $field:ident : $ty:ty),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[repr(C)]
        #[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
        $vis struct $name {
            $($(#[$field_meta])* $field_vis $field: $ty),*
        }

        impl $crate::gpu_struct::WgslType for $name {
            const ALIGN: usize = {
                let mut a = 1;
                $(if <$ty as $crate::gpu_struct::WgslType>::ALIGN > a {
                    a = <$ty as $crate::gpu_struct::WgslType>::ALIGN;
                })*
                a
            };
            const SIZE: usize = std::mem::size_of::<$name>();
            fn wgsl() -> String {
                stringify!($name).to_owned()
            }
        }

        impl $crate::gpu_struct::GpuStruct for $name {
            fn fields() -> Vec<$crate::gpu_struct::WgslField> {
                vec![$($crate::gpu_struct::WgslField {
                    name: stringify!($field),
                    ty: <$ty as $crate::gpu_struct::WgslType>::wgsl(),
                    rust_offset: std::mem::offset_of!($name, $field),
                    wgsl_align: <$ty as $crate::gpu_struct::WgslType>::ALIGN,
                    wgsl_size: <$ty as $crate::gpu_struct::WgslType>::SIZE,
                }),*]
            }
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn declarations_and_layouts_follow_the_one_definition() {
        crate::gpu_struct! {
            struct Nested {
                x: u32,
                y: u32,
                pad: [u32; 2],
                inner: Outer,
            }
        }
        crate::gpu_struct! {
            struct Outer {
                v: [f32; 4],
                w: [u32; 2],
                s: f32,
                t: f32,
            }
        }
        assert_eq!(
            Outer::declaration(),
            "struct Outer {\n    v: vec4<f32>,\n    w: vec2<u32>,\n    s: f32,\n    t: f32,\n}\n"
        );
        assert_eq!(Outer::wgsl_layout(), (vec![0, 16, 24, 28], 32));
        Outer::check_layout().unwrap();
        assert_eq!(<Outer as WgslType>::ALIGN, 16);
        assert_eq!(Nested::wgsl_layout(), (vec![0, 4, 8, 16], 48));
        Nested::check_layout().unwrap();
        assert!(Nested::declaration().contains("    inner: Outer,\n"));
        crate::gpu_struct! {
            struct WithArray {
                head: u32,
                tail: u32,
                pad: [u32; 2],
                levels: [[u32; 4]; 3],
            }
        }
        assert!(WithArray::declaration().contains("    levels: array<vec4<u32>, 3>,\n"));
        assert_eq!(WithArray::wgsl_layout(), (vec![0, 4, 8, 16], 64));
        WithArray::check_layout().unwrap();
    }

    /// A struct whose fields WGSL would place elsewhere than Rust fails the check: a `u32`
    /// before a `vec4` sits at 0 in both, but the vector then starts at 16 in WGSL and at 4 in a
    /// packed Rust struct — impossible with `repr(C)` and `[f32; 4]` (align 4), which is exactly
    /// the mismatch the check exists to catch.
    #[test]
    fn a_misaligned_field_is_caught() {
        crate::gpu_struct! {
            struct Misaligned {
                tag: u32,
                v: [f32; 4],
                pad: [u32; 2],
                more: u32,
            }
        }
        let e = Misaligned::check_layout().unwrap_err();
        assert!(
            e.contains("Misaligned.v: Rust offset 4, WGSL offset 16"),
            "{e}"
        );
    }
}
