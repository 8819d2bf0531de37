#!/usr/bin/env bash
# Copies the browser IDE's third-party libraries, unmodified, from the npm
# registry into ../assets/vendor: uPlot (charts) and CodeMirror 5 (the
# editor), at the versions package-lock.json pins. scripts/test runs it and
# checks that the committed copies are what it produces.
set -euo pipefail
cd "$(dirname "$0")"
npm ci --no-audit --no-fund --ignore-scripts --silent
out=../assets/vendor
rm -rf "$out"
mkdir -p "$out/uplot" "$out/codemirror"
cp node_modules/uplot/dist/uPlot.iife.min.js node_modules/uplot/dist/uPlot.min.css node_modules/uplot/LICENSE "$out/uplot/"
cp node_modules/codemirror/lib/codemirror.js node_modules/codemirror/lib/codemirror.css \
   node_modules/codemirror/addon/mode/simple.js node_modules/codemirror/LICENSE "$out/codemirror/"
