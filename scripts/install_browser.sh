#!/usr/bin/env bash
# Install Debian's chromium for the browser test of report.html (tests/reference/test_report_html.py),
# if missing. Without apt-get it says so and leaves the test to skip itself.
set -euo pipefail
for b in chromium chromium-browser google-chrome; do
  if command -v "$b" >/dev/null 2>&1; then exit 0; fi
done
if ! command -v apt-get >/dev/null 2>&1; then
  echo "tmfem: no chromium and no apt-get: the browser test of report.html will be skipped" >&2
  exit 0
fi
SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
echo "tmfem: installing chromium (headless browser test of report.html)"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq chromium >/dev/null
