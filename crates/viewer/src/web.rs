//! The page (wasm32 + WebGPU): the viewer in a `<canvas>`, its settings from the URL
//! (`?scene=cornell&pipeline=forward-plus&lights=2000`: the names of `manylights view`'s
//! options), scenes fetched from the page's `assets/` folder, logs to the console, and
//! every failure (a panic, an error, no WebGPU) written on the page instead of a blank
//! canvas. The native twin is `native.rs`, with the same functions.
//!
//! The page reports its state on `<body data-state="...">` for people and the headless
//! browser test: `loading`, `running`, `done` (a `frames=N` run drew its frames; the last
//! frame's pixels are in `window.manylightsFrame` as a PNG data URL) or `error` (the text is
//! in `#status`).

use std::cell::RefCell;
use std::future::Future;
use std::path::Path;

use anyhow::{Context as _, anyhow, bail};
use clap::Parser;
use manylights::scene::MemoryFiles;
use manylights::{LoadedScene, Renderer};
use wasm_bindgen::JsCast;
use wasm_bindgen::prelude::wasm_bindgen;
use wasm_bindgen_futures::JsFuture;
use winit::event_loop::{EventLoop, EventLoopProxy};
use winit::platform::web::{EventLoopExtWebSys, WindowAttributesExtWebSys, WindowExtWebSys};
use winit::window::{Window, WindowAttributes};

use crate::ViewArgs;
use crate::app::{App, AppEvent, SceneRequest};

pub type Exit = ();

/// Screenshots are the canvas's pixels: that frame is drawn without the panels.
pub const SCREENSHOT_FROM_WINDOW: bool = true;

/// The id of the page's canvas (`web/index.html`).
const CANVAS_ID: &str = "manylights";
/// Where the page's scenes are, relative to the page.
const ASSETS: &str = "assets";

/// The page's options: exactly `manylights view`'s.
#[derive(Parser)]
#[command(name = "manylights", no_binary_name = true)]
struct PageArgs {
    #[command(flatten)]
    view: ViewArgs,
}

thread_local! {
    /// The running viewer's event loop, for what the page's script hands over (files).
    static PROXY: RefCell<Option<EventLoopProxy<AppEvent>>> = const { RefCell::new(None) };
}

pub fn main() {
    std::panic::set_hook(Box::new(|info| {
        console_error_panic_hook::hook(info);
        show_state("error", &format!("manylights panicked: {info}"));
    }));
    let _ = console_log::init_with_level(log::Level::Warn);
    show_state("loading", "loading…");
    let started = page_args().and_then(|args| {
        let event_loop = EventLoop::<AppEvent>::with_user_event()
            .build()
            .context("starting the page's event loop")?;
        let app = App::new(args, event_loop.create_proxy());
        PROXY.with(|proxy| *proxy.borrow_mut() = Some(event_loop.create_proxy()));
        event_loop.spawn_app(app);
        Ok(())
    });
    if let Err(error) = started {
        show_state("error", &format!("{error:#}"));
    }
}

/// The URL's query as `view` options: `?a=1&b` is `--a 1 --b`, and `?post.bloom=0.05`
/// (a setting's path) `--set post.bloom=0.05` (`manylights_lab::cli::url_query_args`).
fn page_args() -> anyhow::Result<ViewArgs> {
    let search = window()?.location().search().map_err(js_error)?;
    let pairs = search
        .trim_start_matches('?')
        .split('&')
        .filter(|p| !p.is_empty())
        .map(|pair| {
            let (key, value) = pair.split_once('=').unwrap_or((pair, ""));
            Ok((decode(key)?, decode(value)?))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let argv = manylights_lab::cli::url_query_args(pairs);
    let args = PageArgs::try_parse_from(&argv)
        .map_err(|e| anyhow!("the page's URL asks for settings that do not parse:\n{e}"))?
        .view;
    let size_given = search
        .trim_start_matches('?')
        .split('&')
        .any(|pair| pair.split('=').next() == Some("size"));
    if args.screenshot.is_some() {
        bail!(
            "the page cannot write files: `screenshot=` is for the native viewer; press F12 (or the Screenshot button) to download the frame"
        );
    }
    if size_given {
        // A fixed size (tests, screenshots): the canvas is exactly that many pixels.
        // The size is a setting like any other (`--size`, `size=`, `--set view.size=...`).
        let (width, height) = args.frame.settings().map_err(anyhow::Error::msg)?.view.size;
        let canvas = canvas()?;
        let style = canvas.style();
        let ratio = window()?.device_pixel_ratio();
        let css = |pixels: u32| format!("{}px", f64::from(pixels) / ratio);
        style.set_property("width", &css(width)).map_err(js_error)?;
        style
            .set_property("height", &css(height))
            .map_err(js_error)?;
    }
    Ok(args)
}

fn decode(text: &str) -> anyhow::Result<String> {
    let text = text.replace('+', " ");
    js_sys::decode_uri_component(&text)
        .map(String::from)
        .map_err(|_| anyhow!("the URL has a malformed escape in '{text}'"))
}

fn window() -> anyhow::Result<web_sys::Window> {
    web_sys::window().ok_or_else(|| anyhow!("no browser window"))
}

fn document() -> anyhow::Result<web_sys::Document> {
    window()?
        .document()
        .ok_or_else(|| anyhow!("no document in the browser window"))
}

fn canvas() -> anyhow::Result<web_sys::HtmlCanvasElement> {
    document()?
        .get_element_by_id(CANVAS_ID)
        .ok_or_else(|| anyhow!("the page has no <canvas id=\"{CANVAS_ID}\">"))?
        .dyn_into::<web_sys::HtmlCanvasElement>()
        .map_err(|_| anyhow!("#{CANVAS_ID} is not a canvas"))
}

fn js_error(value: wasm_bindgen::JsValue) -> anyhow::Error {
    anyhow!(
        "{}",
        value
            .as_string()
            .or_else(|| js_sys::JSON::stringify(&value).ok().map(String::from))
            .unwrap_or_else(|| format!("{value:?}"))
    )
}

/// Writes the page's state (`data-state` on `<body>`) and its message (`#status`, shown
/// over the canvas for errors). Logs errors to the console too.
fn show_state(state: &str, message: &str) {
    if state == "error" {
        log::error!("{message}");
    }
    let Ok(document) = document() else {
        return;
    };
    if let Some(body) = document.body() {
        let _ = body.set_attribute("data-state", state);
    }
    if let Some(status) = document.get_element_by_id("status") {
        status.set_text_content(Some(message));
    }
}

/// A named scene (`sponza`, `lamps`: fetched from `assets/`), a procedural one (`cornell`,
/// `pillars`), or the URL of a `.gltf`/`.glb` file; the files it references are fetched
/// beside it.
pub async fn load_scene(spec: &str) -> anyhow::Result<LoadedScene> {
    if let Some(procedural) = LoadedScene::procedural(spec) {
        return Ok(procedural?);
    }
    let urls: Vec<String> = match LoadedScene::asset_files(spec) {
        [] => vec![spec.to_string()],
        files => files
            .iter()
            .map(|file| format!("{ASSETS}/{file}"))
            .collect(),
    };
    let mut scene: Option<manylights::scene::Scene> = None;
    for url in urls {
        let loaded = fetch_scene_file(&url).await?;
        match &mut scene {
            Some(scene) => scene.append(loaded),
            None => scene = Some(loaded),
        }
    }
    let scene = scene.ok_or_else(|| anyhow!("scene '{spec}' names no file"))?;
    Ok(LoadedScene::from_scene(spec, scene))
}

/// A `.gltf`/`.glb`/`.obj` file fetched from `url`, with the files it references fetched
/// beside it.
async fn fetch_scene_file(url: &str) -> anyhow::Result<manylights::scene::Scene> {
    let bytes = fetch(url).await?;
    let folder = url.rsplit_once('/').map_or("", |(folder, _)| folder);
    let mut files = MemoryFiles::new();
    for referenced in manylights::scene::referenced_files(url, &bytes)? {
        let referenced_url = if folder.is_empty() {
            referenced.uri.clone()
        } else {
            format!("{folder}/{}", referenced.uri)
        };
        files.insert(referenced.path, fetch(&referenced_url).await?);
    }
    Ok(manylights::scene::load_from_memory(url, &bytes, &files)?)
}

/// The page's file picker and drop target hand a user's files here (`index.html`): one
/// `.gltf` or `.glb`, and for a `.gltf` the buffers and images it references, by name. The
/// scene replaces the current one; an error is shown in the panel and the current scene
/// stays.
#[wasm_bindgen]
pub fn open_scene_files(names: Vec<String>, contents: js_sys::Array) {
    let loaded = scene_from_files(&names, &contents);
    let name = names
        .iter()
        .find(|n| is_scene_file(n))
        .cloned()
        .unwrap_or_else(|| names.join(", "));
    let event = AppEvent::SceneLoaded {
        request: SceneRequest::FromPage,
        spec: name.clone(),
        loaded: Box::new(loaded),
    };
    if !send_to_viewer(event) {
        log::warn!("{name} was opened after the viewer stopped: not shown");
    }
}

/// The page's script asks the measure panel to run a matrix (`window.manylightsMeasure`
/// in `index.html`; the tests use it): the lab's matrix as JSON, its fields as in a
/// `bench.json`'s `matrix` (what is left out keeps the lab's default; the scene is the one
/// shown). The page says `data-measure="running"`, then `done` or `error`, on `<body>`.
#[wasm_bindgen]
pub fn measure(matrix_json: &str) -> Result<(), String> {
    let matrix = manylights_lab::lab::BenchMatrix::from_json(matrix_json)
        .map_err(|e| format!("the matrix to measure does not parse: {e:#}"))?;
    let event = AppEvent::Measure(Box::new(matrix));
    if send_to_viewer(event) {
        Ok(())
    } else {
        Err("the viewer is not running".into())
    }
}

fn set_measure_state(state: &str) {
    if let Some(body) = document().ok().and_then(|d| d.body()) {
        let _ = body.set_attribute("data-measure", state);
    }
}

/// The measure panel started a run.
pub fn measure_started() {
    set_measure_state("running");
}

/// The measure panel's run ended: the page shows its charts over the canvas and offers
/// its `bench.json` and `REPORT.md` for download (`window.manylightsBench` holds the JSON);
/// returns where the results are, for the panel.
pub fn measure_ended(outcome: Result<&manylights_lab::lab::BenchReport, &str>) -> String {
    let shown = match outcome {
        Ok(report) => show_measurement(report),
        Err(error) => Err(anyhow!("{error}")),
    };
    match shown {
        Ok(()) => {
            set_measure_state("done");
            "the charts, bench.json and REPORT.md are over the canvas (close them to see it)".into()
        }
        Err(error) => {
            let error = format!("{error:#}");
            log::error!("{error}");
            if let Some(body) = document().ok().and_then(|d| d.body()) {
                let _ = body.set_attribute("data-measure-error", &error);
            }
            set_measure_state("error");
            error
        }
    }
}

/// Text for HTML.
fn escape_html(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A link that downloads `text` as `file`.
fn download_link(file: &str, media_type: &str, text: &str) -> String {
    let data = String::from(js_sys::encode_uri_component(text));
    format!("<a download=\"{file}\" href=\"data:{media_type};charset=utf-8,{data}\">{file}</a>")
}

/// Each configuration's error map against the full-frame reference, inline, with its
/// FLIP, seam and blotch measures: where the error sits, not only how large its mean is.
fn error_maps_html(report: &manylights_lab::lab::BenchReport) -> anyhow::Result<String> {
    use base64::Engine as _;
    let mut figures = String::new();
    for result in &report.results {
        let Some(map) = &result.accuracy.error_map else {
            continue;
        };
        let png = manylights_lab::report::error_map_png(map)?;
        let data = base64::engine::general_purpose::STANDARD.encode(png);
        let number = |value: Option<f64>| value.map_or("-".to_string(), |v| format!("{v:.3}"));
        let caption = format!(
            "{}, {} lights: FLIP {}, seams {}, blotch {}",
            result.config.variant(),
            result.config.lights,
            number(result.accuracy.flip_at_reference_exposure),
            number(result.accuracy.seam_ratio),
            number(result.accuracy.blotch),
        );
        figures.push_str(&format!(
            "<figure><img class=\"error-map\" alt=\"error map: {caption}\" src=\"data:image/png;base64,{data}\"><figcaption>{caption}</figcaption></figure>",
            caption = escape_html(&caption),
        ));
    }
    if figures.is_empty() {
        return Ok(figures);
    }
    Ok(format!(
        "<h3>Error maps</h3><p>Each frame against its full-frame reference: white where \
         equal, red brighter, blue darker, full at 10%; grey where not judged.</p>{figures}"
    ))
}

fn show_measurement(report: &manylights_lab::lab::BenchReport) -> anyhow::Result<()> {
    let json = serde_json::to_string_pretty(report).context("writing bench.json")?;
    js_sys::Reflect::set(
        &window_object()?,
        &"manylightsBench".into(),
        &json.clone().into(),
    )
    .map_err(js_error)?;
    let charts = manylights_lab::report::charts(report)?;
    let chart = |file: &str| {
        charts
            .iter()
            .find(|c| c.file == file)
            .map_or(String::new(), |c| c.svg.clone())
    };
    let matrix = &report.matrix;
    // Chrome rounds timestamps to 100 us unless its WebGPU developer features are on: say
    // which this browser did.
    let quantized = report
        .results
        .iter()
        .flat_map(|r| &r.passes)
        .all(|p| ((p.median_ms * 10.0).round() - p.median_ms * 10.0).abs() < 1e-6);
    let resolution = if quantized {
        "This browser rounded every pass time to 100 µs: compare times well above that."
    } else {
        "This browser's pass times are finer than 100 µs."
    };
    let adapter = if report.adapter.is_empty() {
        "this browser's WebGPU adapter"
    } else {
        &report.adapter
    };
    let html = format!(
        "<button type=\"button\" onclick=\"this.parentElement.hidden = true\">Close</button>\
         <h2>{count} configurations measured on {adapter}{stopped}</h2>\
         <p>GPU times are medians of {frames} frames after a warm-up, from WebGPU timestamps \
         per pass, which browsers may quantize (Chrome rounds them to 100 µs unless its \
         WebGPU developer features are on). {resolution} {no_timestamps}\
         Errors are the mean relative HDR error at {samples} pixels against the f64 reference, \
         computed here in the page.</p>\
         <p>{bench} (draw it again with <code>manylights bench --replot FOLDER</code>) · {markdown}</p>\
         {error_chart}{time_chart}{error_maps}",
        count = report.results.len(),
        adapter = escape_html(adapter),
        stopped = if report.interrupted { " (stopped)" } else { "" },
        frames = matrix.frames,
        no_timestamps = if report.timestamps {
            ""
        } else {
            "This browser gave no timestamps: there are no GPU times. "
        },
        samples = matrix.reference_samples,
        bench = download_link("bench.json", "application/json", &json),
        markdown = download_link(
            "REPORT.md",
            "text/markdown",
            &manylights_lab::report::report_markdown(report)
        ),
        error_chart = chart("error_vs_time.svg"),
        time_chart = chart("gpu_ms_vs_lights.svg"),
        error_maps = error_maps_html(report)?,
    );
    let section = document()?
        .get_element_by_id("measure")
        .ok_or_else(|| anyhow!("the page has no #measure section"))?;
    section.set_inner_html(&html);
    section.remove_attribute("hidden").map_err(js_error)?;
    Ok(())
}

/// Hands what the page's script gave to the running viewer; false once it has stopped.
fn send_to_viewer(event: AppEvent) -> bool {
    PROXY.with(|proxy| {
        proxy
            .borrow()
            .as_ref()
            .is_some_and(|proxy| proxy.send_event(event).is_ok())
    })
}

fn is_scene_file(name: &str) -> bool {
    let lower = name.to_ascii_lowercase();
    lower.ends_with(".gltf") || lower.ends_with(".glb")
}

fn scene_from_files(names: &[String], contents: &js_sys::Array) -> anyhow::Result<LoadedScene> {
    if names.len() != contents.length() as usize {
        bail!("{} file names for {} files", names.len(), contents.length());
    }
    let mut scene_file = None;
    let mut files = MemoryFiles::new();
    for (name, content) in names.iter().zip(contents.iter()) {
        let bytes = js_sys::Uint8Array::new(&content).to_vec();
        if is_scene_file(name) && scene_file.is_none() {
            scene_file = Some((name.clone(), bytes));
        } else {
            files.insert(name.clone(), bytes);
        }
    }
    let Some((name, bytes)) = scene_file else {
        bail!(
            "none of {} is a .gltf or .glb file (open the scene file, with the buffers and images a .gltf references)",
            names.join(", ")
        );
    };
    let scene = manylights::scene::load_from_memory(&name, &bytes, &files)
        .with_context(|| format!("loading {name}"))?;
    Ok(LoadedScene::from_scene(&name, scene))
}

async fn fetch(url: &str) -> anyhow::Result<Vec<u8>> {
    let response = JsFuture::from(window()?.fetch_with_str(url))
        .await
        .map_err(js_error)
        .with_context(|| format!("fetching {url}"))?;
    let response: web_sys::Response = response
        .dyn_into()
        .map_err(|_| anyhow!("fetching {url}: not a response"))?;
    if !response.ok() {
        bail!(
            "fetching {url}: HTTP {} {}",
            response.status(),
            response.status_text()
        );
    }
    let buffer = JsFuture::from(response.array_buffer().map_err(js_error)?)
        .await
        .map_err(js_error)
        .with_context(|| format!("reading {url}"))?;
    Ok(js_sys::Uint8Array::new(&buffer).to_vec())
}

/// The window is the page's canvas, sized by the page (CSS), or exactly by `size=` in the
/// URL.
pub fn window_attributes(
    attributes: WindowAttributes,
    _args: &ViewArgs,
) -> anyhow::Result<WindowAttributes> {
    Ok(attributes.with_canvas(Some(canvas()?)))
}

/// Spawns `future` on the page's event loop; its result comes back through `proxy` as
/// `event(result)`. The browser cannot wait here, so nothing is returned now.
pub fn launch<T: 'static>(
    proxy: &EventLoopProxy<AppEvent>,
    future: impl Future<Output = T> + 'static,
    event: impl FnOnce(T) -> AppEvent + 'static,
) -> Option<T> {
    let proxy = proxy.clone();
    wasm_bindgen_futures::spawn_local(async move {
        let result = future.await;
        if proxy.send_event(event(result)).is_err() {
            log::warn!("the viewer stopped before this finished: its result is not shown");
        }
    });
    None
}

/// The canvas's pixels as a PNG data URL: the frame just presented (call in the same
/// task, before the browser shows it: a WebGPU canvas is read while its texture exists).
fn canvas_png(window: &Window) -> anyhow::Result<String> {
    let canvas = window
        .canvas()
        .ok_or_else(|| anyhow!("the window has no canvas"))?;
    canvas.to_data_url().map_err(js_error)
}

/// The frame just drawn without the UI, downloaded as `path`'s file name.
pub fn save_screenshot(_renderer: &Renderer, window: &Window, path: &Path) -> anyhow::Result<()> {
    let url = canvas_png(window)?;
    let link = document()?
        .create_element("a")
        .map_err(js_error)?
        .dyn_into::<web_sys::HtmlAnchorElement>()
        .map_err(|_| anyhow!("cannot make a download link"))?;
    link.set_href(&url);
    link.set_download(&path.display().to_string());
    link.click();
    Ok(())
}

/// A `frames=N` run drew its frames: the last one's pixels go to
/// `window.manylightsFrame` and the page says `done` with the frame-rate line. (`finish`
/// writes `screenshot=` natively; the page refuses that option when it starts.)
pub fn frames_done(
    summary: &str,
    window: &Window,
    _finish: impl FnOnce() -> anyhow::Result<()>,
) -> anyhow::Result<()> {
    let url = canvas_png(window)?;
    js_sys::Reflect::set(&window_object()?, &"manylightsFrame".into(), &url.into())
        .map_err(js_error)?;
    show_state("done", summary);
    Ok(())
}

fn window_object() -> anyhow::Result<wasm_bindgen::JsValue> {
    Ok(window()?.into())
}

/// The viewer stopped: an error is written on the page.
pub fn stopped(outcome: &anyhow::Result<()>) {
    if let Err(error) = outcome {
        show_state("error", &format!("{error:#}"));
    }
}

/// A scene asked for from the UI or handed over by the page loaded, or failed to: the page
/// says which on `<body data-scene>` or `data-load-error` (the panel shows the error too).
pub fn scene_loaded(spec: &str, error: Option<&String>) {
    let Some(body) = document().ok().and_then(|d| d.body()) else {
        return;
    };
    match error {
        None => {
            let _ = body.set_attribute("data-scene", spec);
            let _ = body.remove_attribute("data-load-error");
        }
        Some(error) => {
            log::warn!("could not load {spec}: {error}");
            let _ = body.set_attribute("data-load-error", &format!("{spec}: {error}"));
        }
    }
}

/// The GPU and scene are ready: the page says `running` (and hides its status line).
pub fn started() {
    show_state("running", "");
}
