//! What the library needs of a wgpu device, as values: an engine that creates its own
//! device merges them into its `DeviceDescriptor` first ([`DeviceRequirements::merge_into`]),
//! and [`crate::GpuContext::from_device`] refuses a device that lacks one, naming the
//! limit, the value needed and the value the device has.
//!
//! ```no_run
//! # async fn engine() -> Result<(), manylights_gpu::GpuError> {
//! use manylights_gpu::{DeviceRequirements, GpuContext, wgpu};
//! let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
//! let adapter = instance
//!     .request_adapter(&wgpu::RequestAdapterOptions::default())
//!     .await
//!     .expect("an adapter");
//! // The engine's own descriptor, with what the library needs merged in.
//! let mut descriptor = wgpu::DeviceDescriptor::default();
//! let needs = DeviceRequirements::minimum().with_storage_binding(64 << 20);
//! needs.merge_into(&mut descriptor, &adapter);
//! let (device, queue) = adapter.request_device(&descriptor).await.expect("a device");
//! // The engine keeps its device, its queue and its callbacks; the library's errors come
//! // back through error scopes as `GpuError`s.
//! let context = GpuContext::from_device(instance, adapter, device, queue, &needs)?;
//! # let _ = context;
//! # Ok(())
//! # }
//! ```

/// What the library's passes need of a device.
#[derive(Debug, Clone, PartialEq)]
pub struct DeviceRequirements {
    /// Limits the device must have at least (at most, for the alignments).
    pub limits: wgpu::Limits,
    /// Features the library uses where the adapter has them (none is required): timestamp
    /// queries for per-pass GPU times, adapter-specific format features for MSAA counts
    /// beyond 4, the primitive index for the visibility buffer.
    pub optional_features: wgpu::Features,
}

impl DeviceRequirements {
    /// What every program of the library needs: the limits every WebGPU adapter
    /// guarantees (each program fits them: `cargo xtask limits`, docs/webgpu-limits.md),
    /// and no feature.
    pub fn minimum() -> Self {
        Self {
            limits: wgpu::Limits::default(),
            optional_features: wgpu::Features::TIMESTAMP_QUERY
                | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS
                | wgpu::Features::PRIMITIVE_INDEX
                | wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES,
        }
    }

    /// With storage bindings (and buffers) of `bytes`: the largest buffer the frame will
    /// bind, such as the lights' (a million lights need more than WebGPU's 128 MiB
    /// guarantee for the lists and the light tree).
    pub fn with_storage_binding(mut self, bytes: u64) -> Self {
        self.limits.max_storage_buffer_binding_size =
            self.limits.max_storage_buffer_binding_size.max(bytes);
        self.limits.max_buffer_size = self.limits.max_buffer_size.max(bytes);
        self
    }

    /// Merges these requirements into an engine's `descriptor`: each limit becomes the
    /// better of the engine's and ours, and the optional features `adapter` has are added.
    pub fn merge_into(&self, descriptor: &mut wgpu::DeviceDescriptor<'_>, adapter: &wgpu::Adapter) {
        descriptor.required_limits = descriptor
            .required_limits
            .clone()
            .or_better_values_from(&self.limits);
        descriptor.required_features |= adapter.features() & self.optional_features;
    }

    /// Every limit `device_limits` falls short of: (the limit's name, the value needed,
    /// the value the device has).
    pub fn shortfalls(&self, device_limits: &wgpu::Limits) -> Vec<(&'static str, u64, u64)> {
        let mut short = Vec::new();
        self.limits
            .check_limits_with_fail_fn(device_limits, false, |name, needed, has| {
                short.push((name, needed, has));
            });
        short
    }
}
