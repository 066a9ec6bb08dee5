#!/usr/bin/env bash
# Builds lensview's web page into web/dist (or the folder given): the
# library for wasm32-unknown-unknown with Debian's rustc-web (the rustup
# toolchain has no wasm32 std; build-std builds it), then wasm-bindgen.
# Installs what is missing first (apt as root; wasm-bindgen-cli with the
# rustup cargo at Cargo.lock's wasm-bindgen version). Recipe and figures:
# docs/web.md. Threads and SIMD128: web/.cargo/config.toml. Cold build on 2
# busy cores: about 8.5-10 minutes for each of the two; after a change to
# web/, seconds.
set -euo pipefail
web="$(cd "$(dirname "$0")" && pwd)"
root="$(dirname "$web")"
out="${1:-$web/dist}"

need_apt=()
for p in rustc-web cargo-web rust-web-src rust-web-llvm; do
    dpkg -s "$p" > /dev/null 2>&1 || need_apt+=("$p")
done
# rust-web-llvm's /usr/bin/rust-lld links to lld-N without depending on it.
lld_of() { readlink /usr/bin/rust-lld 2> /dev/null || true; }
if [ ${#need_apt[@]} -gt 0 ] || [ ! -e "/usr/bin/$(lld_of)" ]; then
    if [ "$(id -u)" != 0 ]; then
        echo "error: missing ${need_apt[*]} $(lld_of); run web/build.sh as root once (it installs them with apt)" >&2
        exit 1
    fi
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -qq
    apt-get install -y -qq --no-install-recommends rustc-web cargo-web rust-web-src rust-web-llvm > /dev/null
    lld="$(lld_of)"
    [ -n "$lld" ] || { echo "error: /usr/bin/rust-lld is not a link to an lld-N" >&2; exit 1; }
    [ -e "/usr/bin/$lld" ] || apt-get install -y -qq --no-install-recommends "$lld" > /dev/null
fi

# wasm-bindgen-cli must be the version of the wasm-bindgen crate in Cargo.lock.
want="$(awk '/^name = "wasm-bindgen"$/ { getline; gsub(/version = |"/, ""); print; exit }' "$root/Cargo.lock")"
have="$(wasm-bindgen --version 2> /dev/null | awk '{ print $2 }' || true)"
if [ "$have" != "$want" ]; then
    echo "installing wasm-bindgen-cli $want (found: ${have:-none})" >&2
    cargo install -q wasm-bindgen-cli --version "$want"
fi

cd "$web"
# rustup's ~/.cargo/bin shadows /usr/bin: Debian's cargo and rustc by path.
export RUSTC=/usr/bin/rustc RUSTDOC=/usr/bin/rustdoc RUSTC_BOOTSTRAP=1
# Two builds (docs/web.md). pkg/: threads (feature `threads`: the pool),
# atomics and a shared memory (.cargo/config.toml's rustflags), for
# cross-origin isolated pages. pkg-st/: one thread, no atomics and a plain
# memory, for pages that are not (browsers other than Chromium refuse a
# shared memory there); RUSTFLAGS replaces the config's rustflags (SIMD128
# alone: the same kernel, the same bits) and its std is built apart, in
# target-st (Debian's rustc-web ships no wasm32 std).
/usr/bin/cargo build --release --features threads
RUSTFLAGS="-C target-feature=+simd128" /usr/bin/cargo build --release --target-dir target-st
rm -rf "$out"
mkdir -p "$out"
wasm-bindgen --target web --no-typescript --remove-name-section --out-dir "$out/pkg" \
    target/wasm32-unknown-unknown/release/lensview_web.wasm
wasm-bindgen --target web --no-typescript --remove-name-section --out-dir "$out/pkg-st" \
    target-st/wasm32-unknown-unknown/release/lensview_web.wasm
cp www/index.html www/main.js www/worker.js www/panel.js "$out/"
echo "built $out ($(du -b "$out/pkg/lensview_web_bg.wasm" | cut -f1) bytes of wasm with threads, $(du -b "$out/pkg-st/lensview_web_bg.wasm" | cut -f1) on one thread); serve it with web/serve.sh"
