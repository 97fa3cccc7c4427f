#!/usr/bin/env bash
# Regenerates the scene frames the docs show (docs/frames/*), each drawn by
# the command line from a built-in scene after some steps:
#
#   janus2d run SCENE --steps N --every N --svg|--png DIR --size WxH
#
#     --fit each (the camera fits the frame it draws; a scene may say otherwise)
#
# keeps the last frame (step N). Small scenes become SVG, the big ones PNG
# (PNG frames draw no text: tiny-skia has no fonts). JANUS2D overrides the
# command (default: cargo run --release -q -p janus2d-cli --).
#
#   docs/frames/make.sh            # all of them, about a minute in release
#   docs/frames/make.sh bridge     # only the frames whose scene matches
set -euo pipefail
cd "$(dirname "$0")/../.."
out=docs/frames
read -r -a janus <<<"${JANUS2D:-cargo run --release -q -p janus2d-cli --}"
only=${1:-}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

# frame SCENE STEPS svg|png WxH [more run arguments]
frame() {
  local scene=$1 steps=$2 format=$3 size=$4
  shift 4
  [[ -z $only || $scene == *"$only"* ]] || return 0
  local file=${scene//\//_} fit=(--fit each)
  [[ " $* " != *" --fit "* ]] || fit=()
  rm -rf "$tmp/f"
  "${janus[@]}" run "$scene" --steps "$steps" --every "$steps" "--$format" "$tmp/f" \
    --size "$size" "${fit[@]}" --no-progress "$@" >/dev/null
  cp "$tmp/f/frame_00001.$format" "$out/$file.$format"
  echo "$out/$file.$format  ($scene, step $steps, $(du -k "$out/$file.$format" | cut -f1) KB)"
}

# Box2D's benchmark scenes (docs/performance.md).
frame large_pyramid 120 png 240x160
frame many_pyramids 60 png 240x160
frame joint_grid 120 png 240x160
frame tumbler 240 png 240x160
frame smash 60 png 240x160
frame spinner 240 png 240x160 --fit once # (bodies thrown out of the loop would zoom out)
frame rain 600 png 240x160
frame junkyard 240 png 240x160
frame compounds 240 png 240x160
frame washer 240 png 240x160

# The hard cases (docs/accuracy.md, docs/performance.md).
frame single_box 90 svg 240x160
frame hard/pyramid20 300 svg 240x160
frame vertical_stack_12 300 svg 160x240
frame vertical_stack_15 300 svg 160x240
frame vertical_stack_20 300 svg 160x240
frame double_domino 120 svg 240x160
frame confined 300 png 240x160
frame high_mass_ratio_1 300 svg 240x160
frame high_mass_ratio_2 300 svg 240x160
frame high_mass_ratio_3 300 svg 240x160
frame bridge 300 svg 240x160
frame ball_and_chain 60 svg 240x160
frame stretched_chain 60 svg 240x160
frame joint_grid_40 200 png 240x160

# The portal stream (docs/accuracy.md).
frame portal_stream 300 png 240x160
