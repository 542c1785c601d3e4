#!/usr/bin/env bash
# Checks the system libraries hybridgen needs and installs the missing ones from Debian when run as root.
#   - Mesa EGL + the llvmpipe software driver: headless OpenGL for the label rasterizer.
#   - libLLVM >= 17 for Mitsuba's llvm_ad_rgb variant (Dr.Jit aborts on LLVM 15/16 at its first kernel;
#     without a usable LLVM hybridgen falls back to the slower scalar_rgb variant).
#   - with --test: Debian's chromium, the headless browser the gallery tests render pages in.
# Exit status 0 when everything is there (or was installed), 1 with the command to run otherwise.
set -euo pipefail
for_tests=0
[ "${1:-}" = "--test" ] && for_tests=1

multiarch=$(gcc -print-multiarch 2>/dev/null || dpkg-architecture -qDEB_HOST_MULTIARCH 2>/dev/null || echo x86_64-linux-gnu)
libdirs="/usr/lib/$multiarch /usr/lib /usr/lib64 /lib/$multiarch"

have() {  # have FILE: is a library file present in a system library dir?
  for d in $libdirs; do [ -e "$d/$1" ] && return 0; done
  return 1
}

missing=()
have libEGL.so.1 || missing+=(libegl1)
have libEGL_mesa.so.0 || missing+=(libegl-mesa0)
have libgbm.so.1 || missing+=(libgbm1)
have libGL.so.1 || missing+=(libgl1)
have dri/swrast_dri.so || have dri/kms_swrast_dri.so || missing+=(libgl1-mesa-dri)
have libLLVM-19.so || have libLLVM-18.so || have libLLVM-17.so || have libLLVM.so.19.1 || missing+=(libllvm19)
if [ $for_tests = 1 ]; then
  command -v chromium >/dev/null || missing+=(chromium)
fi

if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
  echo "hybridgen setup: installing ${missing[*]} (Debian packages)" >&2
  export DEBIAN_FRONTEND=noninteractive
  apt-get update -qq
  apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
  exit 0
fi
echo "hybridgen setup: missing system libraries; run: sudo apt-get install ${missing[*]}" >&2
exit 1
