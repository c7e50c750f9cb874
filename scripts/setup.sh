#!/usr/bin/env bash
# Everything igen-lerobot needs on a fresh Debian/Ubuntu machine: Debian packages, uv, Python 3.12
# and the locked environment in .venv (all workspace packages: core, sim, hardware).
# Safe to re-run: it only does what is missing.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

# libusb: pyrealsense2 and open3d fail to import without it. EGL/Mesa: headless MuJoCo rendering
# (MUJOCO_GL=egl). ffmpeg: LeRobot's video decoding (torchcodec). xvfb + xdotool: the teleop test
# drives LeRobot's keyboard teleoperator on a virtual X display.
DEBIAN_PACKAGES=(libusb-1.0-0 libegl1 libegl-mesa0 libgl1-mesa-dri libgles2 ffmpeg xvfb xdotool)

missing=()
for pkg in "${DEBIAN_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
done
if ((${#missing[@]})); then
  echo "setup: installing Debian packages: ${missing[*]}"
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

if ! command -v uv >/dev/null 2>&1; then
  echo "setup: installing uv"
  python3 -m pip install --quiet uv || python3 -m pip install --quiet --user uv
  export PATH="$HOME/.local/bin:$PATH"
  hash -r
fi

# uv cannot download interpreters here: use the machine's Python 3.12 (pyenv or system).
find_python() {
  local candidates=("${IGEN_PYTHON:-}" python3.12 /usr/local/bin/python3.12 /usr/bin/python3.12)
  if command -v pyenv >/dev/null 2>&1; then
    candidates+=("$(pyenv root)"/versions/3.12*/bin/python3.12)
  fi
  candidates+=("$HOME"/.pyenv/versions/3.12*/bin/python3.12)
  for c in "${candidates[@]}"; do
    [ -n "$c" ] || continue
    if "$c" -c 'import sys; assert sys.version_info[:2] == (3, 12)' >/dev/null 2>&1; then
      "$c" -c 'import sys; print(sys.executable)'
      return 0
    fi
  done
  return 1
}
python=$(find_python) || { echo "setup: Python 3.12 not found; install it or set IGEN_PYTHON=/path/to/python3.12" >&2; exit 1; }

export UV_PYTHON_DOWNLOADS=never
uv sync --locked --all-packages --all-extras --python "$python" --quiet
# franky-sim (the FR3 simulator the franky backend is tested against) needs mujoco 4: its own env.
uv sync --locked --project tools/franky_sim --python "$python" --quiet

# Bytecode. Where PYTHONDONTWRITEBYTECODE is set (as on this project's CI machines) Python never
# caches what it compiles, so every process -- each test's igen-*/lerobot-* subprocess -- compiles
# torch, lerobot and the rest from source again (~8 s each). Compile the environments once per
# lock, and our own packages on every run (only changed files are recompiled).
for venv in .venv tools/franky_sim/.venv; do
  stamp="$venv/.bytecode-$(cat uv.lock tools/franky_sim/uv.lock | sha1sum | cut -c1-12)"
  if [ ! -e "$stamp" ]; then
    echo "setup: compiling $venv to bytecode (once per lock)"
    # (not the packages' own test suites: a sixth of the files, never imported here)
    "$venv/bin/python" -m compileall -q -j 0 -x '/tests/' "$venv"/lib/python3.12/site-packages >/dev/null 2>&1 || true
    rm -f "$venv"/.bytecode-*
    touch "$stamp"
  fi
done
.venv/bin/python -m compileall -q -j 0 igen_lerobot sim hardware plugins tests tools/franky_sim/serve.py >/dev/null 2>&1 || true
echo "setup: environment ready in .venv ($("$python" --version), $(uv --version))"
