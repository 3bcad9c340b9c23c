//! GPU errors as values: wgpu validation, out-of-memory and internal errors are captured
//! with error scopes and returned, never printed and ignored.

/// What went wrong on the GPU side.
#[derive(Debug, thiserror::Error)]
pub enum GpuError {
    #[error(
        "no GPU adapter found{hint}. On a machine without a GPU install Mesa's lavapipe \
         (Debian/Ubuntu: `sudo apt-get install mesa-vulkan-drivers libvulkan1`) and run again"
    )]
    NoAdapter { hint: String },

    #[error("WGPU_ADAPTER_NAME='{wanted}' matches no adapter; available: {available}")]
    AdapterNotFound { wanted: String, available: String },

    #[error("could not create the device on {adapter}: {source}")]
    RequestDevice {
        adapter: String,
        #[source]
        source: wgpu::RequestDeviceError,
    },

    #[error("wgpu validation error while {context}: {message}")]
    Validation { context: String, message: String },

    #[error("GPU out of memory while {context}")]
    OutOfMemory { context: String },

    #[error("the GPU device was lost ({reason})")]
    DeviceLost { reason: String },

    #[error("wgpu internal error while {context}: {message}")]
    Internal { context: String, message: String },

    #[error("{what} needs {needed}, but the device limit {limit} is {allowed}")]
    LimitExceeded {
        what: String,
        needed: u64,
        limit: &'static str,
        allowed: u64,
    },

    #[error("shader {module}: {message}")]
    Shader { module: String, message: String },

    #[error("waiting for the GPU failed while {context}: {message}")]
    Poll { context: String, message: String },

    #[error("buffer mapping failed while {context}: {message}")]
    Map { context: String, message: String },

    #[error("unsupported: {0}")]
    Unsupported(String),

    /// An input the caller gave (lights, a camera, a depth texture) that cannot be used:
    /// `what` names it (`lights`, `depth texture`), `problem` says what is wrong with which
    /// part of it. Nothing was changed on the GPU.
    #[error("{what}: {problem}")]
    InvalidInput { what: String, problem: String },
}

impl GpuError {
    pub(crate) fn from_wgpu(context: &str, error: wgpu::Error) -> Self {
        match error {
            wgpu::Error::OutOfMemory { .. } => GpuError::OutOfMemory {
                context: context.into(),
            },
            wgpu::Error::Validation { description, .. } => GpuError::Validation {
                context: context.into(),
                message: description,
            },
            wgpu::Error::Internal { description, .. } => GpuError::Internal {
                context: context.into(),
                message: description,
            },
        }
    }
}

pub type GpuResult<T> = Result<T, GpuError>;
