#!/usr/bin/env bash
# Assemble the web inspector's page into OUT_DIR (docs/web.md):
#   OUT_DIR/index.html, OUT_DIR/app/...        the page (src/web/page)
#   OUT_DIR/lib/<package>/...                  the files the page loads of each pinned npm package,
#                                              with the package's LICENSE next to them
# The packages come from the npm registry, pinned by src/web/page/package-lock.json (`npm ci`, no
# install scripts), installed into a work directory next to OUT_DIR (OUT_DIR.npm, or $VSD_WEB_NPM_DIR),
# so that OUT_DIR holds only what is served and can be installed as it is. The npm step runs only when
# the lockfile changed (a stamp keyed by its hash); the page itself is copied every time (it is small),
# so edits show up.
#
# Usage: scripts/web-assets.sh OUT_DIR
set -euo pipefail

if [[ $# -ne 1 || -z "$1" ]]; then
  echo "usage: $0 OUT_DIR" >&2
  exit 2
fi
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
page="$here/../src/web/page"
out="$1"
mkdir -p "$out"
out="$(cd "$out" && pwd)"
work="${VSD_WEB_NPM_DIR:-$out.npm}"

hash_of() { sha256sum "$@" | sha256sum | cut -c1-16; }
stamp_value="$(hash_of "$page/package.json" "$page/package-lock.json")"
stamp="$work/stamp"

if [[ ! -f "$stamp" || "$(cat "$stamp")" != "$stamp_value" || ! -d "$out/lib" ]]; then
  if ! command -v npm >/dev/null 2>&1; then
    echo "web-assets.sh: npm is missing; install Node.js and npm (Debian: apt-get install npm) to fetch" \
         "the page's libraries (three, elkjs, uplot) pinned by src/web/page/package-lock.json" >&2
    exit 1
  fi
  rm -rf "$work/node_modules"
  mkdir -p "$work"
  cp "$page/package.json" "$page/package-lock.json" "$work/"
  echo "web-assets.sh: npm ci (three, elkjs, uplot) in $work" >&2
  if ! (cd "$work" && npm ci --ignore-scripts --no-audit --no-fund --loglevel=error >&2); then
    echo "web-assets.sh: npm ci failed (is the npm registry reachable, or the npm cache filled?)" >&2
    exit 1
  fi

  modules="$work/node_modules"
  rm -rf "$out/lib.new"
  # copy PACKAGE FILE...: each FILE (relative to the package) keeps its path under lib/PACKAGE.
  copy() {
    local package="$1"
    shift
    for file in "$@"; do
      if [[ ! -e "$modules/$package/$file" ]]; then
        echo "web-assets.sh: $package has no $file (did the pinned version change its layout?)" >&2
        exit 1
      fi
      mkdir -p "$out/lib.new/$package/$(dirname "$file")"
      cp -R "$modules/$package/$file" "$out/lib.new/$package/$file"
    done
  }
  # three: the ES module build (three.module.js imports three.core.js) and the orbit controls. Meshes
  # come from /api/mesh as arrays, so no loaders are needed.
  copy three LICENSE package.json build/three.module.js build/three.core.js \
       examples/jsm/controls/OrbitControls.js
  # elkjs: the bundled build runs the layout in the page (no worker file to serve).
  copy elkjs LICENSE.md package.json lib/elk.bundled.js
  copy uplot LICENSE package.json dist/uPlot.esm.js dist/uPlot.min.css
  rm -rf "${out:?}/lib"
  mv "$out/lib.new" "$out/lib"
  echo "$stamp_value" >"$stamp"
fi

# The page: replaced whole, so a file deleted from the source does not linger.
rm -rf "$out/app.new"
cp -R "$page/app" "$out/app.new"
rm -rf "$out/app"
mv "$out/app.new" "$out/app"
cp "$page/index.html" "$out/index.html"
