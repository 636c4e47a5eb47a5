#!/usr/bin/env bash
# Run the web inspector's browser tests (run.mjs) in headless Chromium.
#
#   tests/web/browser/run.sh --server PATH_TO_VSD_WEB --file MODEL_FILE [--artifacts DIR] [-- SERVER ARGS]
#
# Installs playwright-core (pinned by package-lock.json here) with `npm ci` into $VSD_BROWSER_MODULES,
# or next to the server binary (DIR_OF_VSD_WEB/web-browser-npm) — once per lockfile (a stamp keyed by its
# hash). Chromium is $VSD_CHROMIUM, else Debian's /usr/bin/chromium, else `chromium` on the PATH.
# Exits 77 (ctest's skip code) with a message when Node.js or Chromium is missing.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"

skip() {
  echo "SKIPPED: $*" >&2
  exit 77
}

server=""
args=("$@")
for ((i = 0; i < ${#args[@]}; ++i)); do
  [[ "${args[i]}" == "--" ]] && break
  [[ "${args[i]}" == "--server" && $((i + 1)) -lt ${#args[@]} ]] && server="${args[i + 1]}"
done
if [[ -z "$server" ]]; then
  echo "usage: $0 --server PATH_TO_VSD_WEB --file MODEL_FILE [--artifacts DIR] [-- SERVER ARGS]" >&2
  exit 2
fi

command -v node >/dev/null 2>&1 || skip "node (Node.js >= 18) is not installed; the browser tests need it"
node_major="$(node -p 'process.versions.node.split(".")[0]')"
((node_major >= 18)) || skip "node $(node --version) is too old; playwright-core needs Node.js >= 18"

chromium="${VSD_CHROMIUM:-}"
if [[ -z "$chromium" ]]; then
  if [[ -x /usr/bin/chromium ]]; then chromium=/usr/bin/chromium
  else chromium="$(command -v chromium || command -v chromium-browser || true)"; fi
fi
[[ -n "$chromium" && -x "$chromium" ]] ||
  skip "Chromium is not installed (Debian: apt-get install chromium; or set VSD_CHROMIUM)"

modules="${VSD_BROWSER_MODULES:-$(cd "$(dirname "$server")" && pwd)/web-browser-npm}"
stamp_value="$(cat "$here/package.json" "$here/package-lock.json" | sha256sum | cut -c1-16)"
if [[ ! -f "$modules/stamp" || "$(cat "$modules/stamp")" != "$stamp_value" ||
      ! -d "$modules/node_modules/playwright-core" ]]; then
  command -v npm >/dev/null 2>&1 ||
    skip "npm is not installed; it is needed once to install playwright-core into $modules"
  mkdir -p "$modules"
  cp "$here/package.json" "$here/package-lock.json" "$modules/"
  echo "run.sh: npm ci (playwright-core) in $modules" >&2
  # --ignore-scripts: playwright-core downloads no browser; Debian's Chromium is used.
  if ! (cd "$modules" && npm ci --ignore-scripts --no-audit --no-fund --loglevel=error >&2); then
    echo "run.sh: npm ci failed in $modules (is the npm registry reachable?)" >&2
    exit 1
  fi
  echo "$stamp_value" >"$modules/stamp"
fi

exec node "$here/run.mjs" --modules "$modules" --chromium "$chromium" "$@"
