//! `AsyncReadback`: reads a small GPU buffer back without stalling the frame. Each frame
//! copies the buffer into a free slot of a small ring of mappable buffers; the mapping is
//! requested after the submission and collected by a later frame once the GPU got there.
//! The CPU never waits (except in [`AsyncReadback::wait_newest_async`], for reports,
//! tests and the lab, which natively blocks and in the page yields to the browser).

use futures_channel::oneshot;

use crate::context::GpuContext;
use crate::error::{GpuError, GpuResult};

/// What a buffer map's callback sends: whether the mapping succeeded.
pub(crate) type MapResult = Result<(), wgpu::BufferAsyncError>;

/// Requests the mapping of all of `buffer` for reading; the receiver gets the callback's
/// answer (awaited by [`AsyncReadback::wait_newest_async`] and `targets::map_read_async`,
/// checked without waiting by [`AsyncReadback::try_newest`]).
pub(crate) fn request_read_map(buffer: &wgpu::Buffer) -> oneshot::Receiver<MapResult> {
    let (sender, receiver) = oneshot::channel();
    buffer
        .slice(..)
        .map_async(wgpu::MapMode::Read, move |result| {
            let _ = sender.send(result);
        });
    receiver
}

#[derive(Debug)]
enum SlotState {
    Free,
    /// A copy was recorded; the mapping is requested after the submission.
    Copied,
    /// `map_async` was called; its callback answers on this channel.
    Mapping(oneshot::Receiver<MapResult>),
    /// The callback answered (collected by the next [`AsyncReadback::try_newest`]).
    Answered(MapResult),
}

#[derive(Debug)]
struct Slot {
    buffer: wgpu::Buffer,
    state: SlotState,
    /// What the caller said this copy is (e.g. a frame number).
    tag: u64,
}

/// A slot [`AsyncReadback::reserve`] set aside for one copy.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ReservedSlot(usize);

/// A ring of mappable buffers for one source buffer's first `size` bytes.
#[derive(Debug)]
pub struct AsyncReadback {
    slots: Vec<Slot>,
    size: u64,
    /// What is read back, for errors.
    label: String,
}

impl AsyncReadback {
    /// `slots` copies may be in flight at once (3 covers a GPU two frames behind).
    pub fn new(context: &GpuContext, label: &str, size: u64, slots: usize) -> Self {
        Self::new_on(&context.device, label, size, slots)
    }

    /// [`AsyncReadback::new`] for a caller that holds the device alone (the timer).
    pub fn new_on(device: &wgpu::Device, label: &str, size: u64, slots: usize) -> Self {
        let slots = (0..slots.max(1))
            .map(|_| Slot {
                buffer: device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some(label),
                    size,
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
                state: SlotState::Free,
                tag: 0,
            })
            .collect();
        Self {
            slots,
            size,
            label: label.to_string(),
        }
    }

    /// Records a copy of `source` from `offset` into a free slot, tagged `tag`. Returns
    /// false (and records nothing) when every slot is still in flight: that frame is not
    /// read back.
    pub fn record_copy(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        source: &wgpu::Buffer,
        offset: u64,
        tag: u64,
    ) -> bool {
        let size = self.size;
        let Some(slot) = self
            .slots
            .iter_mut()
            .find(|s| matches!(s.state, SlotState::Free))
        else {
            return false;
        };
        encoder.copy_buffer_to_buffer(source, offset, &slot.buffer, 0, size);
        slot.state = SlotState::Copied;
        slot.tag = tag;
        true
    }

    /// Reserves a free slot, tagged `tag`, for a copy recorded later by
    /// [`AsyncReadback::record_reserved_copy`] (a recorder that holds the readback shared:
    /// the reservation is made while the frame is prepared). The slot counts as copied:
    /// the submission after which [`AsyncReadback::request_maps`] is called must hold the
    /// copy. `None` when every slot is still in flight: that frame is not read back.
    pub fn reserve(&mut self, tag: u64) -> Option<ReservedSlot> {
        let index = self
            .slots
            .iter()
            .position(|s| matches!(s.state, SlotState::Free))?;
        let slot = &mut self.slots[index];
        slot.state = SlotState::Copied;
        slot.tag = tag;
        Some(ReservedSlot(index))
    }

    /// Records the copy of `source` from `offset` into the slot [`AsyncReadback::reserve`]
    /// gave.
    pub fn record_reserved_copy(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        source: &wgpu::Buffer,
        offset: u64,
        slot: ReservedSlot,
    ) {
        if let Some(target) = self.slots.get(slot.0) {
            encoder.copy_buffer_to_buffer(source, offset, &target.buffer, 0, self.size);
        }
    }

    /// Requests the mapping of the copies recorded since the last call; call after the
    /// submission that contains them.
    pub fn request_maps(&mut self) {
        for slot in self
            .slots
            .iter_mut()
            .filter(|s| matches!(s.state, SlotState::Copied))
        {
            slot.state = SlotState::Mapping(request_read_map(&slot.buffer));
        }
    }

    /// The newest copy whose mapping finished (older finished ones are dropped), without
    /// waiting for the GPU.
    pub fn try_newest(&mut self, context: &GpuContext) -> GpuResult<Option<(u64, Vec<u8>)>> {
        // Runs the callbacks of finished mappings; never blocks.
        let _ = context.device.poll(wgpu::PollType::Poll);
        let mut newest: Option<(u64, Vec<u8>)> = None;
        for slot in &mut self.slots {
            if let SlotState::Mapping(receiver) = &mut slot.state {
                match receiver.try_recv() {
                    Ok(Some(result)) => slot.state = SlotState::Answered(result),
                    // A callback that was dropped unanswered: nothing to read.
                    Err(oneshot::Canceled) => {
                        slot.state = SlotState::Answered(Err(wgpu::BufferAsyncError))
                    }
                    Ok(None) => continue,
                }
            }
            let SlotState::Answered(result) = &slot.state else {
                continue;
            };
            // A failed mapping has nothing to read.
            if result.is_ok() {
                let bytes = slot
                    .buffer
                    .slice(..)
                    .get_mapped_range()
                    .map_err(|e| GpuError::Map {
                        context: format!("reading back the {}", self.label),
                        message: e.to_string(),
                    })?
                    .to_vec();
                slot.buffer.unmap();
                if newest.as_ref().is_none_or(|(tag, _)| slot.tag > *tag) {
                    newest = Some((slot.tag, bytes));
                }
            }
            slot.state = SlotState::Free;
        }
        Ok(newest)
    }

    /// Waits for every copy in flight, then returns the newest (reports, tests and the
    /// lab). Natively it blocks on the device; in the page it yields to the browser, which
    /// runs the map callbacks.
    pub async fn wait_newest_async(
        &mut self,
        context: &GpuContext,
    ) -> GpuResult<Option<(u64, Vec<u8>)>> {
        if self
            .slots
            .iter()
            .any(|s| !matches!(s.state, SlotState::Free))
        {
            self.request_maps();
            #[cfg(not(target_arch = "wasm32"))]
            context.wait_idle("waiting for a readback")?;
            for slot in &mut self.slots {
                if let SlotState::Mapping(receiver) = &mut slot.state {
                    // Wait for the callback; `try_newest` reads what it said.
                    let result = receiver.await.unwrap_or(Err(wgpu::BufferAsyncError));
                    slot.state = SlotState::Answered(result);
                }
            }
        }
        self.try_newest(context)
    }

    /// [`AsyncReadback::wait_newest_async`], blocking (native only).
    pub fn wait_newest(&mut self, context: &GpuContext) -> GpuResult<Option<(u64, Vec<u8>)>> {
        crate::block_on(self.wait_newest_async(context))
    }
}
