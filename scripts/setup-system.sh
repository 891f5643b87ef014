#!/usr/bin/env bash
# System set-up that pip cannot do. Never fatal: what is missing degrades with a warning.
# - Dr.Jit 1.5's LLVM backend crashes with Debian's LLVM 14/15 ("Cannot select: fminimum"):
#   install libllvm19; without it the package falls back to Mitsuba's scalar variants.
# - Headless Chromium and its WebDriver (chromium-driver) for the dataset gallery's browser test.
set -u
updated=0
apt_install() {  # apt_install PACKAGE WHY
  if [ "$(id -u)" != 0 ] || ! command -v apt-get >/dev/null 2>&1; then
    echo "setup: warning: $1 is missing and there is no root/apt to install it ($2)"
    return
  fi
  echo "setup: installing $1 ($2)"
  if [ "$updated" = 0 ]; then apt-get update -qq >/dev/null 2>&1; updated=1; fi
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$1" >/dev/null 2>&1 \
    || echo "setup: warning: could not install $1 ($2)"
}
have_llvm() { ls /usr/lib/x86_64-linux-gnu/libLLVM-1[6-9]*.so* /usr/lib/*/libLLVM.so.1[6-9]* \
                 /usr/lib/llvm-1[6-9]/lib/libLLVM*.so* 2>/dev/null | grep -q .; }

have_llvm || apt_install libllvm19 "Dr.Jit's LLVM backend needs LLVM >= 16; else scalar variants"
command -v chromium >/dev/null 2>&1 || apt_install chromium "browser test of the dataset gallery"
command -v chromedriver >/dev/null 2>&1 || apt_install chromium-driver "Selenium drives Chromium in the gallery's browser test"
exit 0
