#!/usr/bin/env bash
# Installs every Debian package MARSala needs to build, test and run. Idempotent: does nothing when all are present,
# otherwise runs `apt-get update` once and installs what is missing.
# --containers: also podman, runc, podman-compose and mmdebstrap, for docker/run.sh and the container test.
# --browser: also chromium, for the live view's browser test (tests/integration/live_view_test.sh; skipped without).
# --prometheus: also prometheus (the server and promtool), for the metrics test (tests/integration/metrics_test.sh,
#   the exposition's promtool check; skipped without). Debian's package enables a prometheus service on :9090.
# --npm: also nodejs and npm, for the MCAP export's test (tests/integration/mcap_export_test.sh reads the file with
#   npm's @mcap/core; skipped without).
# --slurm: also slurm-wlm and munge, for sweeps on Slurm (deploy/sweep.sh --slurm) and their test
#   (tests/integration/slurm_sweep_test.sh starts a private two-node cluster; skipped without).
set -euo pipefail
containers=0 browser=0 prometheus=0 npm=0 slurm=0
for arg in "$@"; do
  case "$arg" in
    --containers) containers=1 ;;
    --browser) browser=1 ;;
    --prometheus) prometheus=1 ;;
    --npm) npm=1 ;;
    --slurm) slurm=1 ;;
    *) echo "install-deps: unknown option '$arg' (known: --containers, --browser, --prometheus, --npm, --slurm)" >&2
       exit 2 ;;
  esac
done

packages=(
  cmake make g++ pkg-config python3
  libeigen3-dev
  libtiff-dev libpng-dev zlib1g-dev libssl-dev
  libcli11-dev
  libgtest-dev libgmock-dev googletest libbenchmark-dev
  # scenarios and run summaries (protobuf), logging
  libprotobuf-dev protobuf-compiler libspdlog-dev libfmt-dev
  # common/bus: both DDS vendors (fastddsgen runs at build time)
  cyclonedds-dev cyclonedds-tools libfastrtps-dev libfastcdr-dev fastddsgen
  # marsala-monitor serve: HTTP server and JSON (header-only / small libraries)
  libcpp-httplib-dev nlohmann-json3-dev
  # multi-process tests run inside a private network namespace (unshare -n, ip link set lo up); the multi-host tests
  # and benches drop multicast with a packet filter (tests/integration/lib.sh, bench/loss_bench.sh)
  iproute2 util-linux nftables
  # deploy/marsala_tools (sweep, experiment, route search) and its tests (tests/python, ctest's tools.pytest), jq for
  # spawn.sh/demo.sh (marsala-world --check --json), the sweep's and experiments' plots
  python3 python3-pytest jq gnuplot-nox
  # the agent's OctoMap (agent/executive/mapping_system.cpp: scans of the laser and rgbd sensors)
  liboctomap-dev
  # DDS Security identities (deploy/security/make-identities.sh, spawn.sh --secure)
  openssl
)

[ "$containers" -eq 1 ] && packages+=(podman runc podman-compose mmdebstrap)
[ "$browser" -eq 1 ] && packages+=(chromium)
[ "$prometheus" -eq 1 ] && packages+=(prometheus)
[ "$slurm" -eq 1 ] && packages+=(slurm-wlm munge)
# Only when the commands are missing: a node installed another way (one that bundles npm) stays as it is.
if [ "$npm" -eq 1 ] && ! { command -v node && command -v npm; } >/dev/null; then packages+=(nodejs npm); fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  exit 0
fi

sudo=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "install-deps: need root or sudo to install: ${missing[*]}" >&2; exit 1; }
  sudo="sudo"
fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
