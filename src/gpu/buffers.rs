//! Buffer creation, binding-size checks, chunking past the binding limit, and async readback.

use std::future::Future;
use std::ops::Range;
use std::pin::Pin;
use std::sync::{Arc, Mutex};
use std::task::{Context, Poll, Waker};

use bytemuck::Pod;
use wgpu::util::DeviceExt;

use super::{GpuContext, GpuError, GpuResult};

/// Usage of every storage buffer we create: bound in kernels, filled by uploads, read back.
const STORAGE: wgpu::BufferUsages = wgpu::BufferUsages::STORAGE
    .union(wgpu::BufferUsages::COPY_SRC)
    .union(wgpu::BufferUsages::COPY_DST);

impl GpuContext {
    /// Fails with a readable error when `bytes` cannot be bound as one storage buffer.
    pub(crate) fn check_binding(&self, what: &str, bytes: u64) -> GpuResult<()> {
        let limit = self
            .limits
            .max_storage_buffer_binding_size
            .min(self.limits.max_buffer_size);
        if bytes > limit {
            return Err(GpuError::BindingTooLarge {
                what: what.to_string(),
                bytes,
                limit,
            });
        }
        Ok(())
    }

    /// A storage buffer holding `data` (at least 4 bytes, so empty inputs still bind).
    pub fn storage_buffer<T: Pod>(&self, label: &str, data: &[T]) -> GpuResult<wgpu::Buffer> {
        let bytes: &[u8] = bytemuck::cast_slice(data);
        self.check_binding(label, bytes.len() as u64)?;
        if bytes.len() < 4 {
            return self.storage_buffer_zeroed(label, 4);
        }
        Ok(self
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytes,
                usage: STORAGE,
            }))
    }

    /// A zero-filled storage buffer of `bytes` bytes (rounded up to a multiple of 4, at least 4).
    pub fn storage_buffer_zeroed(&self, label: &str, bytes: u64) -> GpuResult<wgpu::Buffer> {
        let size = bytes.max(4).next_multiple_of(4);
        self.check_binding(label, size)?;
        Ok(self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size,
            usage: STORAGE,
            mapped_at_creation: false,
        }))
    }

    /// A uniform buffer initialised with `value`, writable later with `queue.write_buffer`.
    pub(crate) fn uniform_buffer<T: Pod>(&self, label: &str, value: &T) -> wgpu::Buffer {
        self.device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents: bytemuck::bytes_of(value),
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            })
    }

    /// Copies the first `len` elements of `buffer` back to the CPU.
    ///
    /// Natively this blocks in `device.poll`; in the browser it awaits the map callback, which
    /// the event loop delivers. Device errors recorded meanwhile are returned instead of data.
    pub(crate) async fn read_buffer<T: Pod>(
        &self,
        buffer: &wgpu::Buffer,
        len: usize,
    ) -> GpuResult<Vec<T>> {
        let bytes = (len * size_of::<T>()) as u64;
        if bytes == 0 {
            return Ok(Vec::new());
        }
        let size = bytes.next_multiple_of(wgpu::COPY_BUFFER_ALIGNMENT);
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = self.device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(buffer, 0, &staging, 0, size);
        self.queue.submit([encoder.finish()]);

        let mapped = MapFuture::default();
        let signal = mapped.clone();
        staging.map_async(wgpu::MapMode::Read, .., move |result| {
            signal.complete(result)
        });
        self.poll_wait()?;
        mapped
            .await
            .map_err(|e| GpuError::Readback(e.to_string()))?;
        self.check()?;

        let view = staging
            .get_mapped_range(..)
            .map_err(|e| GpuError::Readback(e.to_string()))?;
        let out = bytemuck::pod_collect_to_vec(&view[..bytes as usize]);
        drop(view);
        staging.unmap();
        Ok(out)
    }
}

/// Splits `count` elements of `elem_bytes` bytes into ranges that each fit one storage binding
/// of at most `max_binding_bytes`, with every range starting at a byte offset that is a multiple
/// of `offset_alignment` (the adapter's `min_storage_buffer_offset_alignment`).
///
/// Kernels that can exceed the binding limit run once per range with a bound sub-slice.
pub fn binding_chunks(
    count: u64,
    elem_bytes: u64,
    max_binding_bytes: u64,
    offset_alignment: u64,
) -> Vec<Range<u64>> {
    if count == 0 || elem_bytes == 0 {
        return Vec::new();
    }
    // Chunk lengths must keep every start aligned: a multiple of lcm(elem, align) / elem elements.
    let lcm = elem_bytes / gcd(elem_bytes, offset_alignment.max(1)) * offset_alignment.max(1);
    let step = (lcm / elem_bytes).max(1);
    let per_chunk = ((max_binding_bytes / elem_bytes) / step * step).max(step);
    (0..count.div_ceil(per_chunk))
        .map(|i| i * per_chunk..((i + 1) * per_chunk).min(count))
        .collect()
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 { a } else { gcd(b, a % b) }
}

/// A one-shot future resolved by a buffer-map callback; `Send` so it satisfies wgpu natively.
#[derive(Clone, Default)]
struct MapFuture(Arc<Mutex<MapState>>);

#[derive(Default)]
struct MapState {
    result: Option<Result<(), wgpu::BufferAsyncError>>,
    waker: Option<Waker>,
}

impl MapFuture {
    fn complete(&self, result: Result<(), wgpu::BufferAsyncError>) {
        if let Ok(mut state) = self.0.lock() {
            state.result = Some(result);
            if let Some(waker) = state.waker.take() {
                waker.wake();
            }
        }
    }
}

impl Future for MapFuture {
    type Output = Result<(), wgpu::BufferAsyncError>;

    fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Self::Output> {
        let Ok(mut state) = self.0.lock() else {
            return Poll::Ready(Err(wgpu::BufferAsyncError));
        };
        match state.result.take() {
            Some(result) => Poll::Ready(result),
            None => {
                state.waker = Some(cx.waker().clone());
                Poll::Pending
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::binding_chunks;

    #[test]
    fn chunks_cover_everything_with_aligned_starts() {
        for &(count, elem, max, align) in &[
            (10u64, 4u64, 16u64, 4u64),
            (1_000_003, 12, 1 << 20, 256),
            (7, 4, 1 << 30, 256),
            (1 << 22, 8, 128 << 20, 64),
        ] {
            let chunks = binding_chunks(count, elem, max, align);
            assert_eq!(chunks.first().map(|r| r.start), Some(0));
            assert_eq!(chunks.last().map(|r| r.end), Some(count));
            for pair in chunks.windows(2) {
                assert_eq!(pair[0].end, pair[1].start);
            }
            for r in &chunks {
                assert_eq!(
                    (r.start * elem) % align,
                    0,
                    "{r:?} misaligned for {elem} B elements"
                );
                assert!(
                    (r.end - r.start) * elem <= max,
                    "{r:?} too large for {max} B bindings"
                );
            }
        }
        assert!(binding_chunks(0, 4, 16, 4).is_empty());
    }
}
