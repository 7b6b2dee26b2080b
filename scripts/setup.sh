# Shared by scripts/run and scripts/test: install missing Debian packages, configure, build.
# Sourced, not executed.

LANCER_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
LANCER_BUILD="${LANCER_BUILD:-$LANCER_ROOT/build}"

LANCER_PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libglfw3-dev libimgui-dev libglm-dev libosmesa6-dev libgl-dev xvfb xauth
  libtbb-dev nlohmann-json3-dev libcli11-dev libstb-dev
  libgtest-dev libbenchmark-dev libembree-dev gnuplot-nox povray
  clang clang-format libclang-rt-14-dev
  libharfbuzz-dev libfreetype-dev libfontconfig-dev fonts-liberation
  openscad
)

lancer_install_packages() {
  local missing=()
  for p in "${LANCER_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  echo "lancer: installing Debian packages: ${missing[*]}"
  local sudo=""
  if [ "$(id -u)" -ne 0 ]; then
    if command -v sudo >/dev/null && sudo -n true 2>/dev/null; then
      sudo="sudo"
    else
      echo "lancer: cannot install packages (not root, no sudo). Run:" >&2
      echo "  sudo apt-get install -y ${missing[*]}" >&2
      return 1
    fi
  fi
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq && $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null \
    || { echo "lancer: apt-get failed; run: sudo apt-get install -y ${missing[*]}" >&2; return 1; }
}

# Warnings are errors: the build is kept at zero (docs/testing.md, "Warnings").
lancer_build() {
  cmake -S "$LANCER_ROOT" -B "$LANCER_BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DLANCER_WERROR=ON "$@" >/dev/null \
    && cmake --build "$LANCER_BUILD" --parallel "$(nproc)"
}
