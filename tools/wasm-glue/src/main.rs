//! `wasm-glue INPUT.wasm OUT_DIR`: the page's JS glue and final wasm, as `wasm-bindgen
//! --target web --no-typescript --out-dir OUT_DIR INPUT.wasm` writes them.

use anyhow::Context as _;

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args_os().skip(1);
    let (Some(input), Some(out), None) = (args.next(), args.next(), args.next()) else {
        anyhow::bail!("usage: wasm-glue INPUT.wasm OUT_DIR");
    };
    wasm_bindgen_cli_support::Bindgen::new()
        .input_path(&input)
        .web(true)?
        .typescript(false)
        // The CLI's default: `init()` finds the wasm beside the glue.
        .omit_default_module_path(false)
        .generate(&out)
        .with_context(|| format!("wasm-bindgen on {}", input.to_string_lossy()))
}
