# Sourced by the GPU-machine render scripts (with `bin` and `out` set): the reference view
# they all measure, and `run NAME ARGS...`, which renders it with ARGS and prints the GPU
# timing lines (or the error) under a `=== NAME` header.
common=(render --scene sponza --camera reference --size 1920x1080 --frames 10 --time 1)
run() {
  local name=$1
  shift
  echo "=== $name"
  # EXTRA_ARGS (optional, word-split): flags every run adds, e.g. `--shading blinn-phong`.
  # shellcheck disable=SC2086
  "$bin" "${common[@]}" --out "$out/$name.png" "$@" ${EXTRA_ARGS:-} 2>&1 | grep -E "^gpu|^error"
}
