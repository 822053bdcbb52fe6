#!/usr/bin/env bash
# Renders every frame of a viscompm output directory to PNG with ParaView's pvbatch (under a
# private Xvfb display) and makes a movie of them with ffmpeg:
#   OUTPUT_DIR/render/frame_NNNNN.png and OUTPUT_DIR/render/movie.mp4
# The material is drawn as the particle surface the run wrote (Output/Surface voxel size), smooth-
# shaded, or as spheres, or as a density field (--style); it is coloured by det b^E around 1
# (Figure 5.7: red above, blue below) unless --field says otherwise; colliders are grey surfaces.
# --strip joins the listed frames side by side (4: a 2x2 grid) into one small PNG. Installs
# ParaView, Xvfb and ffmpeg (Debian packages) when they are missing.
#
# Usage: scripts/render.sh OUTPUT_DIR [--style auto|surface|spheres|density] [--field NAME|none]
#          [--size WxH] [--frames all|last|N,M,...] [--range LO HI] [--view iso|x|y|z]
#          [--azimuth DEG] [--elevation DEG] [--zoom F] [--focus X,Y,Z] [--clip x|y|z]
#          [--fps N] [--no-movie] [--strip N,M,... --strip-file FILE.png [--strip-width W]]
#
# A missing or bad option value, a missing directory or a frame that cannot be read (cut short,
# damaged) is one line on stderr naming the option or the file, exit 2 (doc/contracts.md).
set -euo pipefail

usage() { sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//'; }
fail() { echo "render.sh: $*" >&2; exit 2; }
if [ $# -ge 1 ] && { [ "$1" = "--help" ] || [ "$1" = "-h" ]; }; then usage; exit 0; fi
[ $# -ge 1 ] || fail "missing OUTPUT_DIR (usage: scripts/render.sh OUTPUT_DIR [options]; see --help)"
OUTPUT_DIR="$1"; shift
case "$OUTPUT_DIR" in -*) fail "missing OUTPUT_DIR before '$OUTPUT_DIR' (see --help)" ;; esac
if [ ! -d "$OUTPUT_DIR" ]; then fail "$OUTPUT_DIR: no such directory"; fi
# The value of option $1 (given $# - 1 words after it), or a one-line error.
value_of() { [ "$2" -ge 2 ] || fail "$1 needs a value (see --help)"; }
whole() { [[ "$2" =~ ^[1-9][0-9]{0,5}$ ]] || fail "$1: '$2' is not a positive whole number"; }

FPS=24
MOVIE=1
STRIP=""
STRIP_FILE=""
STRIP_WIDTH=1280
forward=()
while [ $# -gt 0 ]; do
  case "$1" in
    --fps) value_of "$1" $#; whole "$1" "$2"; FPS="$2"; shift 2 ;;
    --no-movie) MOVIE=0; shift ;;
    --strip) value_of "$1" $#; [[ "$2" =~ ^[0-9]+(,[0-9]+)*$ ]] || fail "--strip: '$2' is not frame numbers separated by commas"
             STRIP="$2"; shift 2 ;;
    --strip-file) value_of "$1" $#; STRIP_FILE="$2"; shift 2 ;;
    --strip-width) value_of "$1" $#; whole "$1" "$2"; STRIP_WIDTH="$2"; shift 2 ;;
    --range) [ $# -ge 3 ] || fail "--range needs two values, LO HI (see --help)"; forward+=("$1" "$2" "$3"); shift 3 ;;
    --field|--style|--size|--frames|--view|--clip|--azimuth|--elevation|--zoom|--focus) value_of "$1" $#; forward+=("$1=$2"); shift 2 ;;  # "=": values may be negative
    *) fail "unknown option '$1' (see --help)" ;;
  esac
done
if [ -n "$STRIP" ] && [ -z "$STRIP_FILE" ]; then fail "--strip needs --strip-file FILE.png"; fi
if [ -n "$STRIP_FILE" ] && [ ! -d "$(dirname "$STRIP_FILE")" ]; then fail "--strip-file: $(dirname "$STRIP_FILE"): no such directory"; fi

packages=(paraview python3-paraview python3-h5py xvfb xauth ffmpeg)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "render.sh: installing ${missing[*]}"
  sudo_cmd=()
  [ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# A private X display that does not reset between clients (ParaView's OpenGL needs one). Xvfb
# picks a free display number itself and writes it once it accepts clients (-displayfd), so two
# renders started together cannot take the same display (where the first to end killed the other's).
display_file="$(mktemp)"
Xvfb -displayfd 3 -screen 0 1920x1080x24 -nolisten tcp -noreset 3>"$display_file" >/dev/null 2>&1 &
xvfb_pid=$!
trap 'kill "$xvfb_pid" 2>/dev/null || true; rm -f "$display_file"' EXIT
for _ in $(seq 100); do [ -s "$display_file" ] && break; sleep 0.1; done
display="$(head -n 1 "$display_file")"
[ -n "$display" ] || { echo "render.sh: Xvfb did not start" >&2; exit 3; }

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
DISPLAY=":${display}" pvbatch "$here/render_frames.py" "$OUTPUT_DIR" "${forward[@]}" 2> >(grep -v -e '^\s*$' -e 'Warning' >&2)

shopt -s nullglob
pngs=("$OUTPUT_DIR"/render/frame_*.png)
if [ "$MOVIE" = 1 ] && [ ${#pngs[@]} -ge 2 ]; then
  ffmpeg -y -loglevel error -framerate "$FPS" -pattern_type glob -i "$OUTPUT_DIR/render/frame_*.png" \
    -vf "scale=trunc(iw/2)*2:trunc(ih/2)*2" -c:v libx264 -pix_fmt yuv420p "$OUTPUT_DIR/render/movie.mp4"
  echo "render.sh: $OUTPUT_DIR/render/movie.mp4 (${#pngs[@]} frames at $FPS fps)"
fi

# A strip: the listed frames side by side (four as a 2x2 grid), scaled to STRIP_WIDTH pixels in
# all, in a 256-colour palette (a few hundred kB at most).
if [ -n "$STRIP" ]; then
  inputs=()
  IFS=',' read -r -a strip_frames <<< "$STRIP"
  for f in "${strip_frames[@]}"; do
    png=$(printf '%s/render/frame_%05d.png' "$OUTPUT_DIR" "$f")
    [ -f "$png" ] || fail "--strip: $png not rendered (add frame $f to --frames)"
    inputs+=(-i "$png")
  done
  n=${#strip_frames[@]}
  stack="hstack=inputs=$n"
  [ "$n" = 1 ] && stack="null"
  [ "$n" = 4 ] && stack="xstack=inputs=4:layout=0_0|w0_0|0_h0|w0_h0"
  ffmpeg -y -loglevel error "${inputs[@]}" -filter_complex \
    "$stack,scale=$STRIP_WIDTH:-2:flags=lanczos,split[a][b];[a]palettegen=max_colors=256[p];[b][p]paletteuse=dither=sierra2_4a" \
    -frames:v 1 "$STRIP_FILE"
  echo "render.sh: $STRIP_FILE (frames $STRIP)"
fi
