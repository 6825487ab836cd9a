#!/bin/sh
# The README's pictures, regenerated from the bundled examples (never drawn by hand):
#   docs/img/view3d.png                  the report's 3-D view, last deployment frame (seed)
#   docs/img/response_wing_tip.png       a response plot of the seed (PNG as flexcraft writes it)
#   docs/img/response_hub_translation.png
#   docs/img/root_moments.png            the mast root moment during the compliant deployment
# Needs Debian's chromium (.ci/run installs it) for the 3-D view.
set -eu
cd "$(dirname "$0")/.."
cargo build --release
out=target/screenshots
rm -rf "$out"
mkdir -p "$out" docs/img
./target/release/flexcraft simulate examples/seed.toml --out "$out/seed" --quiet > /dev/null
./target/release/flexcraft simulate examples/seed_compliant.toml --out "$out/compliant" --quiet > /dev/null
cp "$out/seed/plots/response_wing_tip.png" "$out/seed/plots/response_hub_translation.png" docs/img/
cp "$out/compliant/plots/root_moments.png" docs/img/root_moments.png
browser=$(command -v chromium || command -v chromium-browser)
"$browser" --headless --no-sandbox --disable-gpu --hide-scrollbars \
    --user-data-dir="$out/profile" --window-size=1000,820 \
    --screenshot="$PWD/docs/img/view3d.png" \
    "file://$PWD/$out/seed/report.html#only=view3d&view=last" 2> /dev/null
ls -l docs/img
