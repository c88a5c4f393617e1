#!/usr/bin/env bash
# Installs every build and test dependency of nrslam from Debian 12 packages.
# Used by the README quick start and by .ci/run; safe to run again.
set -euo pipefail

packages=(
  build-essential cmake pkg-config
  libeigen3-dev libceres-dev libsuitesparse-dev libgoogle-glog-dev libgflags-dev
  libopencv-dev libembree-dev libcli11-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  parallel chromium
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages already installed"
  exit 0
fi

sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
echo "install_deps: installing ${missing[*]}"
# A mirror that drops a connection now and then should not fail a CI run: apt retries each
# download, and the whole update or install is tried again after a pause.
apt_options=(-o Acquire::Retries=5)
retry() {
  local attempt
  for attempt in 1 2 3; do
    "$@" && return 0
    [ "$attempt" -lt 3 ] && { echo "install_deps: '$*' failed (attempt $attempt of 3), retrying in 20 s" >&2; sleep 20; }
  done
  return 1
}
retry "${sudo_cmd[@]}" apt-get "${apt_options[@]}" update -qq
retry "${sudo_cmd[@]}" env DEBIAN_FRONTEND=noninteractive apt-get "${apt_options[@]}" install -y -qq \
  --no-install-recommends "${missing[@]}"
