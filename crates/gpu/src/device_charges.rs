//! The render's memory account as device allocations see it: every resident buffer and texture
//! is charged to the budget *before* it is created, so a scene too large for the budget is
//! refused with nothing allocated past the limit.
//!
//! The charges are held (as [`fray_core::Reservation`]s) for as long as the resident data lives.
//! What is written at upload also passes through a staging copy of the same size (wgpu's, freed
//! once the queue has run the copy); those copies are charged too, until
//! [`DeviceCharges::finish_uploads`] has waited for the queue.

use crate::bindings;
use crate::{GpuContext, GpuError};
use bytemuck::Pod;
use fray_core::{MemoryBudget, Reservation};

/// Charges made for device allocations, held until this value drops.
#[derive(Debug)]
pub struct DeviceCharges {
    budget: MemoryBudget,
    held: Vec<Reservation>,
    /// The staging copies of uploads not yet known to be freed.
    staging: Vec<Reservation>,
}

impl DeviceCharges {
    /// Charges to `budget`'s account (shared: what is charged here counts against the render).
    pub fn new(budget: &MemoryBudget) -> Self {
        Self {
            budget: budget.clone(),
            held: Vec::new(),
            staging: Vec::new(),
        }
    }

    /// Charges to an account of its own with no limit (test harnesses, which have no render).
    pub fn unlimited() -> Self {
        Self::new(&MemoryBudget::unlimited())
    }

    /// Charges `bytes` of device memory for `what`, or refuses them (a budget error naming
    /// `what`) if the render's total would pass its limit. Call it before the allocation.
    pub fn charge(&mut self, what: &str, bytes: u64) -> Result<(), GpuError> {
        let reservation = self
            .budget
            .reserve(format!("{what} (on the GPU)"), bytes)
            .map_err(GpuError::Budget)?;
        self.held.push(reservation);
        Ok(())
    }

    /// [`DeviceCharges::charge`] for an allocation that is written at once: its bytes and their
    /// staging copy (held until [`DeviceCharges::finish_uploads`]).
    pub fn charge_uploaded(&mut self, what: &str, bytes: u64) -> Result<(), GpuError> {
        let reserve = |what: String| self.budget.reserve(what, bytes).map_err(GpuError::Budget);
        let resident = reserve(format!("{what} (on the GPU)"))?;
        let staging = reserve(format!("{what} (its staging copy for the GPU)"))?;
        self.held.push(resident);
        self.staging.push(staging);
        Ok(())
    }

    /// Waits until the queue has run every upload so far (wgpu frees their staging copies), then
    /// releases the staging charges.
    pub fn finish_uploads(&mut self, ctx: &GpuContext) -> Result<(), GpuError> {
        if self.staging.is_empty() {
            return Ok(());
        }
        ctx.queue.submit([]);
        ctx.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| GpuError::Dispatch {
                pass: "upload",
                reason: format!("waiting for the scene's uploads: {e}"),
            })?;
        self.staging.clear();
        Ok(())
    }

    /// The bytes charged for resident allocations so far (staging copies not included).
    pub fn bytes(&self) -> u64 {
        self.held.iter().map(Reservation::bytes).sum()
    }

    /// [`bindings::upload`], charged first with the bytes it will allocate.
    pub fn upload<T: Pod>(
        &mut self,
        ctx: &GpuContext,
        label: &'static str,
        data: &[T],
        fill: T,
        usage: wgpu::BufferUsages,
    ) -> Result<wgpu::Buffer, GpuError> {
        // An empty array is uploaded as one `fill` element.
        let bytes = std::mem::size_of_val(data).max(std::mem::size_of::<T>()) as u64;
        self.charge_uploaded(label, bytes)?;
        bindings::upload(ctx, label, data, fill, usage)
    }

    /// [`bindings::empty`], charged first with the bytes it will allocate.
    pub fn empty(
        &mut self,
        ctx: &GpuContext,
        label: &'static str,
        bytes: u64,
        usage: wgpu::BufferUsages,
    ) -> Result<wgpu::Buffer, GpuError> {
        self.charge(label, bindings::empty_buffer_size(bytes))?;
        bindings::empty(ctx, label, bytes, usage)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn charges_count_against_the_render_until_dropped_and_refuse_past_its_limit() {
        let budget = MemoryBudget::new(1000);
        let mut charges = DeviceCharges::new(&budget);
        charges.charge("pyramid", 600).unwrap();
        assert_eq!(budget.charged(), 600);
        let refused = charges.charge("samples", 401).unwrap_err().to_string();
        assert!(refused.contains("samples (on the GPU)"), "{refused}");
        assert_eq!(charges.bytes(), 600, "a refused charge holds nothing");
        charges.charge("samples", 400).unwrap();
        assert_eq!(budget.charged(), 1000);
        drop(charges);
        assert_eq!(budget.charged(), 0);
        // Written at once: the staging copy counts as well, until the uploads finish.
        let mut charges = DeviceCharges::new(&budget);
        charges.charge_uploaded("table", 400).unwrap();
        assert_eq!((budget.charged(), charges.bytes()), (800, 400));
        let refused = charges
            .charge_uploaded("grid", 200)
            .unwrap_err()
            .to_string();
        assert!(refused.contains("grid (its staging copy"), "{refused}");
        assert_eq!(
            (budget.charged(), charges.bytes()),
            (800, 400),
            "a refused upload holds nothing"
        );
    }
}
