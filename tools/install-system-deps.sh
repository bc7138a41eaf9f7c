#!/usr/bin/env bash
# Install the Debian packages rockyade needs, only those missing (idempotent, no prompts).
#   python3 + venv : the project's virtual environment
#   yade           : the YADE DEM engine (Debian package, imported from Debian's python3.11)
#   python3-siconos: Siconos, nonsmooth contact dynamics (imported from Debian's python3)
#   chromium       : the headless browser tests/test_assess_report.py renders assess --report's page in
#                    (tests only: the report itself needs no browser; launched without a port or a network)
set -euo pipefail

need=()
command -v python3 >/dev/null 2>&1 || need+=(python3)
if ! python3 -c 'import venv, ensurepip' >/dev/null 2>&1; then need+=(python3-venv); fi
if ! [ -f /usr/lib/x86_64-linux-gnu/yade-double/py/yade/__init__.py ]; then need+=(yade); fi
if ! [ -f /usr/lib/python3/dist-packages/siconos/mechanics/collision/bullet.py ]; then need+=(python3-siconos); fi
command -v chromium >/dev/null 2>&1 || need+=(chromium)

if [ ${#need[@]} -eq 0 ]; then
  echo "system packages: all present"
  exit 0
fi
if [ "$(id -u)" -ne 0 ]; then
  echo "missing Debian packages: ${need[*]}; run 'make' as root (or: sudo apt-get install -y ${need[*]})" >&2
  exit 1
fi
echo "installing Debian packages: ${need[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y --no-install-recommends "${need[@]}"
