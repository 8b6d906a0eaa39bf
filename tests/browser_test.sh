#!/usr/bin/env bash
# The monitoring page in a real browser (tests/browser/page_test.js): Debian's
# headless chromium driven by puppeteer-core, installed here into the build
# tree from tests/browser/package-lock.json (npm ci: the npm cache, or the
# registry the first time). Skipped (exit 77) only without chromium or node,
# which tools/setup.sh installs.
#   tests/browser_test.sh VINES SOURCE_DIR BUILD_DIR
# or, with puppeteer-core installed the same way, another script of
# tests/browser/ (tools/page_deadlines.sh):
#   tests/browser_test.sh VINES SOURCE_DIR BUILD_DIR SCRIPT.js [ARGS...]
set -euo pipefail
vines=$1 source=$2 build=$3
shift 3
chromium=${VINES_CHROMIUM:-/usr/bin/chromium}
if [[ ! -x $chromium ]] || ! command -v node >/dev/null || ! command -v npm >/dev/null; then
  echo "SKIP: the browser test needs chromium ($chromium) and node with npm (bash tools/setup.sh all)"
  exit 77
fi
dir=$build/browser_test
mkdir -p "$dir"
# puppeteer-core as locked, reinstalled when the lock changes.
if ! cmp -s "$source/tests/browser/package-lock.json" "$dir/package-lock.json" || [[ ! -d $dir/node_modules ]]; then
  cp "$source/tests/browser/package.json" "$source/tests/browser/package-lock.json" "$dir/"
  (cd "$dir" && npm ci --no-audit --no-fund --prefer-offline --loglevel=error)
fi
if (($#)); then
  NODE_PATH=$dir/node_modules node "$@"
else
  NODE_PATH=$dir/node_modules node "$source/tests/browser/page_test.js" "$vines" "$source" "$dir/out"
fi
