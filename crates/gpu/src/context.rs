//! `GpuContext`: instance, adapter, device and queue, created headless (a surface for the
//! viewer is made from the same instance later), with error capture.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use crate::error::{GpuError, GpuResult};

/// Which adapter was chosen and what it can do, for logs and reports.
#[derive(Debug, Clone)]
pub struct AdapterSummary {
    pub name: String,
    pub backend: String,
    pub device_type: String,
    pub driver: String,
    pub driver_info: String,
    /// Timestamp queries are available (per-pass GPU times can be measured).
    pub timestamps: bool,
}

impl AdapterSummary {
    /// The summary of the adapter `info` describes, whose device has timestamp queries
    /// or not.
    fn of(info: &wgpu::AdapterInfo, timestamps: bool) -> Self {
        Self {
            name: info.name.clone(),
            backend: format!("{:?}", info.backend),
            device_type: format!("{:?}", info.device_type),
            driver: info.driver.clone(),
            driver_info: info.driver_info.clone(),
            timestamps,
        }
    }
}

impl std::fmt::Display for AdapterSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} ({}, {:?} {}{})",
            self.name,
            self.backend,
            self.device_type,
            self.driver,
            if self.driver_info.is_empty() {
                String::new()
            } else {
                format!(" {}", self.driver_info)
            }
        )
    }
}

/// The GPU: everything the renderer creates resources and submits work with.
#[derive(Debug)]
pub struct GpuContext {
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub summary: AdapterSummary,
    /// Errors raised outside any error scope (kept, not printed and forgotten).
    uncaptured: Arc<Mutex<Vec<String>>>,
    /// Set by the device-lost callback: why the device is gone.
    lost: Arc<Mutex<Option<String>>>,
    /// How the adapter was chosen, to choose it again after a device loss.
    request: AdapterRequest,
    /// The device is an engine's ([`GpuContext::from_device`]): its callbacks are the
    /// engine's, and a lost one is the engine's to recreate.
    engine_owned: bool,
    /// Bind groups and pipelines created through this context (see [`CreationCount`]).
    creations: Arc<Creations>,
}

/// How many bind groups and pipelines a context has created, to hold the prepared frame to
/// its promise: a frame whose settings and inputs did not change creates none (tests read
/// [`GpuContext::created`] around such a frame). Every creation goes through
/// [`GpuContext::create_bind_group`], [`GpuContext::create_render_pipeline`] or
/// [`GpuContext::create_compute_pipeline`], so none escapes the count.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct CreationCount {
    pub bind_groups: u64,
    pub pipelines: u64,
}

#[derive(Debug, Default)]
struct Creations {
    bind_groups: AtomicU64,
    pipelines: AtomicU64,
}

impl GpuContext {
    /// Creates a context without a window. The adapter honours `WGPU_BACKEND` (e.g.
    /// `vulkan`), `WGPU_ADAPTER_NAME` (a case-insensitive substring of the adapter's name)
    /// and `WGPU_POWER_PREF` (default: high performance).
    pub fn new_headless() -> GpuResult<Self> {
        Self::new_headless_with(&AdapterRequest::from_env())
    }

    /// Creates a context without a window on the adapter `request` asks for.
    pub fn new_headless_with(request: &AdapterRequest) -> GpuResult<Self> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        block_on(Self::headless_async(instance, request))
    }

    /// Creates a context whose adapter can present to `surface` (the viewer's window),
    /// chosen as [`GpuContext::new_headless_with`] chooses.
    pub fn for_surface(
        instance: wgpu::Instance,
        surface: &wgpu::Surface<'_>,
        request: &AdapterRequest,
    ) -> GpuResult<Self> {
        block_on(Self::for_surface_async(instance, surface, request))
    }

    /// [`GpuContext::for_surface`] without blocking: the browser cannot block its thread,
    /// so the page awaits this.
    pub async fn for_surface_async(
        instance: wgpu::Instance,
        surface: &wgpu::Surface<'_>,
        request: &AdapterRequest,
    ) -> GpuResult<Self> {
        let adapter = choose_adapter(&instance, request, Some(surface)).await?;
        Self::from_adapter(instance, adapter, request.clone()).await
    }

    /// A new device after this one was lost: the adapter is chosen again (a reset driver
    /// may present a new one) the way it was chosen first, compatible with `surface` when
    /// given. Every resource must be recreated on the new context.
    pub fn recreate(&self, surface: Option<&wgpu::Surface<'_>>) -> GpuResult<Self> {
        if self.engine_owned {
            return Err(GpuError::Unsupported(
                "the device is the engine's: the engine creates its new device, and a new context with GpuContext::from_device".into(),
            ));
        }
        block_on(async {
            let adapter = choose_adapter(&self.instance, &self.request, surface).await?;
            Self::from_adapter(self.instance.clone(), adapter, self.request.clone()).await
        })
    }

    /// A context without a window on an adapter chosen as `request` asks, without
    /// blocking: the viewer's measure panel gets a device of its own with it (in the page
    /// a WebGPU adapter gives one device only, so the adapter is requested again).
    pub async fn headless_async(
        instance: wgpu::Instance,
        request: &AdapterRequest,
    ) -> GpuResult<Self> {
        let adapter = choose_adapter(&instance, request, None).await?;
        Self::from_adapter(instance, adapter, request.clone()).await
    }

    /// How this context's adapter was chosen (to choose another the same way).
    pub fn request(&self) -> &AdapterRequest {
        &self.request
    }

    /// Why the device was lost, once it has been (by a driver reset, a GPU hang, running
    /// out of device memory or [`wgpu::Device::destroy`]); `None` while it works.
    pub fn device_lost(&self) -> Option<String> {
        self.lost.lock().ok().and_then(|lost| lost.clone())
    }

    /// [`GpuContext::device_lost`] as an error. Polls the device first (without waiting):
    /// wgpu reports a loss through a callback that runs when the device is polled.
    pub fn check_device(&self) -> GpuResult<()> {
        if self.device_lost().is_none() {
            let _ = self.device.poll(wgpu::PollType::Poll);
        }
        match self.device_lost() {
            Some(reason) => Err(GpuError::DeviceLost { reason }),
            None => Ok(()),
        }
    }

    /// Creates the device on a chosen adapter (the viewer picks one compatible with its
    /// surface and comes through here too).
    pub async fn from_adapter(
        instance: wgpu::Instance,
        adapter: wgpu::Adapter,
        request: AdapterRequest,
    ) -> GpuResult<Self> {
        let info = adapter.get_info();
        let adapter_features = adapter.features();
        let optional_features = optional_features(request.limits);
        let required_features = adapter_features & optional_features;
        let timestamps = adapter_features.contains(wgpu::Features::TIMESTAMP_QUERY);
        let required_limits = match request.limits {
            // The adapter's own limits: the many-light buffers (1M lights, long cluster
            // lists) need more than WebGPU's defaults.
            DeviceLimits::Adapter => adapter.limits(),
            DeviceLimits::WebGpuDefaults => wgpu::Limits::default(),
        };
        let (device, queue) = adapter
            .request_device(&wgpu::DeviceDescriptor {
                label: Some("manylights device"),
                required_features,
                required_limits,
                experimental_features: wgpu::ExperimentalFeatures::disabled(),
                memory_hints: wgpu::MemoryHints::Performance,
                trace: wgpu::Trace::Off,
            })
            .await
            .map_err(|source| GpuError::RequestDevice {
                adapter: info.name.clone(),
                source,
            })?;
        let uncaptured = Arc::new(Mutex::new(Vec::new()));
        let sink = Arc::clone(&uncaptured);
        device.on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
            log::error!("uncaptured wgpu error: {error}");
            if let Ok(mut errors) = sink.lock() {
                errors.push(error.to_string());
            }
        }));
        let lost = Arc::new(Mutex::new(None));
        let lost_sink = Arc::clone(&lost);
        device.set_device_lost_callback(move |reason, message| {
            log::error!("GPU device lost ({reason:?}): {message}");
            if let Ok(mut lost) = lost_sink.lock() {
                *lost = Some(if message.is_empty() {
                    format!("{reason:?}")
                } else {
                    format!("{reason:?}: {message}")
                });
            }
        });
        let summary = AdapterSummary::of(&info, timestamps);
        log::info!("GPU: {summary}");
        Ok(Self {
            instance,
            adapter,
            device,
            queue,
            summary,
            uncaptured,
            lost,
            request,
            engine_owned: false,
            creations: Arc::default(),
        })
    }

    /// A context over a device an engine created itself (its instance, adapter, device and
    /// queue, shared: wgpu's handles are reference-counted). Nothing of the engine's is
    /// replaced: its uncaptured-error and device-lost callbacks stay its own, and the
    /// library reports its own validation errors through error scopes, as [`GpuError`]s
    /// from the call that raised them. A device that lacks one of `needs` (merge them into
    /// the descriptor first: [`crate::DeviceRequirements::merge_into`]) is refused, naming
    /// the limit, the value needed and the value it has.
    ///
    /// What the library cannot see on such a device: errors raised outside its scopes (the
    /// engine's callback gets them; [`GpuContext::take_uncaptured_errors`] stays empty) and
    /// the device's loss ([`GpuContext::device_lost`] stays `None`: the engine's callback
    /// is told, and the library's calls then fail). [`GpuContext::recreate`] is refused:
    /// the engine makes its new device, and a new context from it.
    pub fn from_device(
        instance: wgpu::Instance,
        adapter: wgpu::Adapter,
        device: wgpu::Device,
        queue: wgpu::Queue,
        needs: &crate::DeviceRequirements,
    ) -> GpuResult<Self> {
        let info = adapter.get_info();
        if let Some((limit, needed, allowed)) = needs.shortfalls(&device.limits()).first() {
            return Err(GpuError::LimitExceeded {
                what: format!("the engine's device on {}", info.name),
                needed: *needed,
                limit,
                allowed: *allowed,
            });
        }
        let timestamps = device.features().contains(wgpu::Features::TIMESTAMP_QUERY);
        let summary = AdapterSummary::of(&info, timestamps);
        Ok(Self {
            instance,
            adapter,
            device,
            queue,
            summary,
            uncaptured: Arc::default(),
            lost: Arc::default(),
            request: AdapterRequest::from_env(),
            engine_owned: true,
            creations: Arc::default(),
        })
    }

    /// Whether the device is an engine's ([`GpuContext::from_device`]), not the library's.
    pub fn engine_owned(&self) -> bool {
        self.engine_owned
    }

    /// The bind groups and pipelines created through this context so far.
    pub fn created(&self) -> CreationCount {
        CreationCount {
            bind_groups: self.creations.bind_groups.load(Ordering::Relaxed),
            pipelines: self.creations.pipelines.load(Ordering::Relaxed),
        }
    }

    /// Creates a bind group, counted ([`CreationCount`]).
    pub fn create_bind_group(&self, desc: &wgpu::BindGroupDescriptor) -> wgpu::BindGroup {
        self.creations.bind_groups.fetch_add(1, Ordering::Relaxed);
        self.device.create_bind_group(desc)
    }

    /// Creates a render pipeline, counted ([`CreationCount`]).
    pub fn create_render_pipeline(
        &self,
        desc: &wgpu::RenderPipelineDescriptor,
    ) -> wgpu::RenderPipeline {
        self.creations.pipelines.fetch_add(1, Ordering::Relaxed);
        self.device.create_render_pipeline(desc)
    }

    /// Creates a compute pipeline, counted ([`CreationCount`]).
    pub fn create_compute_pipeline(
        &self,
        desc: &wgpu::ComputePipelineDescriptor,
    ) -> wgpu::ComputePipeline {
        self.creations.pipelines.fetch_add(1, Ordering::Relaxed);
        self.device.create_compute_pipeline(desc)
    }

    /// The MSAA sample counts (of 1, 2, 4 and 8) that both the HDR and the depth target
    /// support on this device: 1 and 4 everywhere (WebGPU's guarantee), 2 and 8 where the
    /// adapter offers them.
    pub fn msaa_sample_counts(&self) -> Vec<u32> {
        let adapter_specific = self
            .device
            .features()
            .contains(wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES);
        let supports = |format: wgpu::TextureFormat, count: u32| {
            let flags = if adapter_specific {
                self.adapter.get_texture_format_features(format).flags
            } else {
                format
                    .guaranteed_format_features(self.device.features())
                    .flags
            };
            flags.sample_count_supported(count)
        };
        [1, 2, 4, 8]
            .into_iter()
            .filter(|&count| {
                count == 1
                    || (supports(crate::HDR_FORMAT, count) && supports(crate::DEPTH_FORMAT, count))
            })
            .collect()
    }

    /// Runs `work` inside validation, out-of-memory and internal error scopes and turns
    /// any error it raised into a [`GpuError`] naming `context`.
    pub fn scoped<T>(&self, context: &str, work: impl FnOnce() -> T) -> GpuResult<T> {
        let internal = self.device.push_error_scope(wgpu::ErrorFilter::Internal);
        let out_of_memory = self.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = self.device.push_error_scope(wgpu::ErrorFilter::Validation);
        let value = work();
        let scopes = [validation, out_of_memory, internal];
        self.finish_scopes(context, scopes)?;
        Ok(value)
    }

    /// Pops the scopes `scoped` pushed (innermost first) and reports the first error.
    #[cfg(not(target_arch = "wasm32"))]
    fn finish_scopes(&self, context: &str, scopes: [wgpu::ErrorScopeGuard; 3]) -> GpuResult<()> {
        let errors = scopes.map(|scope| pollster::block_on(scope.pop()));
        // On a lost device every call fails; the loss is the reason to report.
        self.check_device()?;
        match errors.into_iter().flatten().next() {
            Some(error) => Err(GpuError::from_wgpu(context, error)),
            None => Ok(()),
        }
    }

    /// In the browser a scope's error arrives only after control returns to the page: the
    /// scopes are popped asynchronously and their errors join the uncaptured ones (the
    /// viewer shows them; the page's test fails on them), named by `context`.
    #[cfg(target_arch = "wasm32")]
    fn finish_scopes(&self, context: &str, scopes: [wgpu::ErrorScopeGuard; 3]) -> GpuResult<()> {
        let sink = Arc::clone(&self.uncaptured);
        let context = context.to_string();
        // Popped now (scopes nest: a later `scoped` pushes its own); awaited later.
        let pops = scopes.map(|scope| scope.pop());
        wasm_bindgen_futures::spawn_local(async move {
            for pop in pops {
                if let Some(error) = pop.await {
                    let message = GpuError::from_wgpu(&context, error).to_string();
                    log::error!("{message}");
                    if let Ok(mut errors) = sink.lock() {
                        errors.push(message);
                    }
                }
            }
        });
        self.check_device()
    }

    /// `error`, or [`GpuError::DeviceLost`] when the device was lost: after a loss every
    /// operation fails (a buffer map, a validation error on an invalid resource), and the
    /// loss is the cause worth reporting.
    pub fn explain(&self, error: GpuError) -> GpuError {
        match self.check_device() {
            Err(lost) => lost,
            Ok(()) => error,
        }
    }

    /// Errors raised outside any scope since the last call (e.g. by a surface present).
    pub fn take_uncaptured_errors(&self) -> Vec<String> {
        self.uncaptured
            .lock()
            .map(|mut errors| std::mem::take(&mut *errors))
            .unwrap_or_default()
    }

    /// Blocks until the submission `index` has finished (frame pacing: a renderer waits
    /// for the frame submitted a few frames ago, never for the one just submitted).
    pub fn wait_for_submission(
        &self,
        index: wgpu::SubmissionIndex,
        context: &str,
    ) -> GpuResult<()> {
        self.wait(
            wgpu::PollType::Wait {
                submission_index: Some(index),
                timeout: None,
            },
            context,
        )
    }

    /// Blocks until all submitted work has finished.
    pub fn wait_idle(&self, context: &str) -> GpuResult<()> {
        self.wait(wgpu::PollType::wait_indefinitely(), context)
    }

    /// Polls the device with `poll` (a waiting kind); a failure is the device's loss if it
    /// was lost, else a poll error naming `context`.
    fn wait(&self, poll: wgpu::PollType, context: &str) -> GpuResult<()> {
        self.device
            .poll(poll)
            .map(|_| ())
            .map_err(|e| match self.device_lost() {
                Some(reason) => GpuError::DeviceLost { reason },
                None => GpuError::Poll {
                    context: context.into(),
                    message: e.to_string(),
                },
            })
    }

    /// Checks a buffer size against the device limits before creating it.
    pub fn check_buffer_size(&self, what: &str, bytes: u64, storage: bool) -> GpuResult<()> {
        let limits = self.device.limits();
        if bytes > limits.max_buffer_size {
            return Err(GpuError::LimitExceeded {
                what: what.into(),
                needed: bytes,
                limit: "max_buffer_size",
                allowed: limits.max_buffer_size,
            });
        }
        if storage && bytes > limits.max_storage_buffer_binding_size {
            return Err(GpuError::LimitExceeded {
                what: what.into(),
                needed: bytes,
                limit: "max_storage_buffer_binding_size",
                allowed: limits.max_storage_buffer_binding_size,
            });
        }
        Ok(())
    }

    /// Checks a 2D texture size against the device limits before creating it.
    pub fn check_texture_size(&self, what: &str, width: u32, height: u32) -> GpuResult<()> {
        let max = self.device.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 {
            return Err(GpuError::Unsupported(format!(
                "{what}: zero-sized texture {width}x{height}"
            )));
        }
        let largest = width.max(height);
        if largest > max {
            return Err(GpuError::LimitExceeded {
                what: format!("{what} ({width}x{height})"),
                needed: largest as u64,
                limit: "max_texture_dimension_2d",
                allowed: max as u64,
            });
        }
        Ok(())
    }
}

/// Runs a GPU future (device creation, a readback) to its end: every blocking call of the
/// workspace is its `_async` twin run by this. Natively that blocks; the browser cannot
/// block its thread (a map's callback runs only when control returns to it), so there the
/// blocking calls are errors that say what to use instead: the page awaits the twins
/// ([`GpuContext::for_surface_async`], `Renderer::read_hdr_async`, the lab's `run_async`).
#[cfg(not(target_arch = "wasm32"))]
pub fn block_on<T, E: From<GpuError>>(future: impl Future<Output = Result<T, E>>) -> Result<T, E> {
    pollster::block_on(future)
}

#[cfg(target_arch = "wasm32")]
pub fn block_on<T, E: From<GpuError>>(_future: impl Future<Output = Result<T, E>>) -> Result<T, E> {
    Err(GpuError::Unsupported(
        "the browser cannot wait for the GPU: the page awaits the `_async` twin of this call (a lost device needs the page reloaded)".into(),
    )
    .into())
}

/// Returns control to whoever polls the future once (it is woken at once, so a blocking
/// executor goes straight on): a long GPU job written as one async function (the lab's
/// runs) yields with it after every frame, so a viewer that polls the job once per
/// displayed frame keeps drawing.
pub async fn yield_now() {
    struct YieldNow {
        yielded: bool,
    }
    impl Future for YieldNow {
        type Output = ();
        fn poll(
            mut self: std::pin::Pin<&mut Self>,
            context: &mut std::task::Context<'_>,
        ) -> std::task::Poll<()> {
            if self.yielded {
                return std::task::Poll::Ready(());
            }
            self.yielded = true;
            context.waker().wake_by_ref();
            std::task::Poll::Pending
        }
    }
    YieldNow { yielded: false }.await
}

/// Which adapter to use, and the limits its device is created with.
#[derive(Debug, Clone, PartialEq)]
pub struct AdapterRequest {
    /// A case-insensitive substring of the adapter's name; an error if none matches.
    pub name: Option<String>,
    pub power_preference: wgpu::PowerPreference,
    pub limits: DeviceLimits,
}

/// The limits a device is created with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DeviceLimits {
    /// Everything the adapter has (what the renderer uses: a million lights need more
    /// than WebGPU guarantees).
    #[default]
    Adapter,
    /// Only what every WebGPU adapter guarantees (8 storage buffers per stage, 4 bind
    /// groups, 128 MiB per binding, 16 KiB of workgroup storage, 256 invocations): a
    /// native device that validates as strictly as the smallest browser
    /// (`MANYLIGHTS_LIMITS=webgpu`; the tests render every program under it).
    WebGpuDefaults,
}

impl AdapterRequest {
    /// `WGPU_ADAPTER_NAME`, `WGPU_POWER_PREF` (high performance unless told otherwise) and
    /// `MANYLIGHTS_LIMITS` (`webgpu`: [`DeviceLimits::WebGpuDefaults`]).
    pub fn from_env() -> Self {
        Self {
            name: std::env::var("WGPU_ADAPTER_NAME").ok(),
            power_preference: wgpu::PowerPreference::from_env()
                .unwrap_or(wgpu::PowerPreference::HighPerformance),
            limits: match std::env::var("MANYLIGHTS_LIMITS").as_deref() {
                Ok("webgpu") => DeviceLimits::WebGpuDefaults,
                _ => DeviceLimits::Adapter,
            },
        }
    }
}

/// Picks the adapter: by name if asked (an error if nothing matches), else the default
/// request with the power preference.
async fn choose_adapter(
    instance: &wgpu::Instance,
    request: &AdapterRequest,
    surface: Option<&wgpu::Surface<'_>>,
) -> GpuResult<wgpu::Adapter> {
    // Adapters are listed only to find one by name: the browser's WebGPU lists none (it
    // hands out one adapter per request).
    if let Some(wanted) = request.name.clone() {
        let mut adapters = instance.enumerate_adapters(wgpu::Backends::all()).await;
        if let Some(surface) = surface {
            adapters.retain(|a| a.is_surface_supported(surface));
        }
        let wanted_lower = wanted.to_lowercase();
        let names: Vec<String> = adapters.iter().map(|a| a.get_info().name).collect();
        return adapters
            .into_iter()
            .find(|a| a.get_info().name.to_lowercase().contains(&wanted_lower))
            .ok_or(GpuError::AdapterNotFound {
                wanted,
                available: if names.is_empty() {
                    "none".into()
                } else {
                    names.join(", ")
                },
            });
    }
    instance
        .request_adapter(&wgpu::RequestAdapterOptions {
            power_preference: request.power_preference,
            compatible_surface: surface,
            ..Default::default()
        })
        .await
        .map_err(|e| GpuError::NoAdapter {
            hint: match std::env::var("WGPU_BACKEND") {
                Ok(backend) => format!(" for WGPU_BACKEND={backend} ({e})"),
                Err(_) => format!(" ({e})"),
            },
        })
}

/// The features a device asks for where the adapter has them. Timestamp queries are
/// optional everywhere. The primitive index (the visibility buffer's indexed raster) and
/// adapter-specific format features (MSAA at 2 and 8 samples, beyond WebGPU's guaranteed
/// 1 and 4) only with the adapter's limits, so a device at WebGPU's defaults is WebGPU
/// core (the visibility buffer then fetches its vertices itself; MSAA offers 4x).
fn optional_features(limits: DeviceLimits) -> wgpu::Features {
    let timestamp_features =
        wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS;
    match limits {
        DeviceLimits::Adapter => {
            timestamp_features
                | wgpu::Features::PRIMITIVE_INDEX
                | wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES
        }
        DeviceLimits::WebGpuDefaults => timestamp_features,
    }
}
