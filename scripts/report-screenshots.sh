#!/usr/bin/env bash
# Screenshots of the top of every real-data report page that
# scripts/real-data.sh wrote (target/real-data/report-*/report.html): the
# verdicts and the first Bode plot, as a reader opens the page, into
# docs/real-data/report-NAME.png, reduced to a palette by pngquant (about a
# third of the size, no visible change). Needs Chromium and pngquant
# (Debian: apt-get install chromium pngquant).
# Usage: scripts/report-screenshots.sh
set -euo pipefail
cd "$(dirname "$0")/.."
browser=$(command -v chromium || command -v chromium-browser || command -v google-chrome)
mkdir -p docs/real-data
for page in target/real-data/report-*/report.html; do
    name=$(basename "$(dirname "$page")")
    "$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
        --window-size=800,1250 --virtual-time-budget=3000 \
        --screenshot="docs/real-data/$name.png" "file://$PWD/$page" 2>/dev/null
    pngquant --quality=60-90 --speed 1 --force --strip --output "docs/real-data/$name.png" \
        "docs/real-data/$name.png"
done
ls -l docs/real-data/report-*.png
