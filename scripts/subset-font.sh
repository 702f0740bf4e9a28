#!/usr/bin/env bash
# Remakes crates/plot/fonts/DejaVuSans-mms.ttf, the PNG backend's font: a
# subset of DejaVu Sans (Debian's fonts-dejavu-core) with printable ASCII,
# Latin-1, Greek, dashes, arrows, the minus sign and comparison symbols.
# Needs fontTools (pip install fonttools); not part of any build.
set -euo pipefail
cd "$(dirname "$0")/.."
src=${1:-/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf}
pyftsubset "$src" \
    --unicodes="U+0020-007E,U+00A0-00FF,U+0393-03A9,U+03B1-03C9,U+2009,U+2013,U+2014,U+2026,U+2190-2193,U+2212,U+2264,U+2265,U+221E" \
    --layout-features='kern' \
    --output-file=crates/plot/fonts/DejaVuSans-mms.ttf
cp /usr/share/doc/fonts-dejavu-core/copyright crates/plot/fonts/LICENSE-DejaVu.txt
