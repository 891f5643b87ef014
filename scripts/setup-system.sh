#!/usr/bin/env bash
# System set-up that pip cannot do: Dr.Jit 1.5's LLVM backend crashes with Debian's LLVM 14/15
# ("Cannot select: fminimum"), so install libllvm19 where we can. Never fatal: without it the
# package falls back to Mitsuba's scalar variants with a warning.
set -u
have_llvm() { ls /usr/lib/x86_64-linux-gnu/libLLVM-1[6-9]*.so* /usr/lib/*/libLLVM.so.1[6-9]* \
                 /usr/lib/llvm-1[6-9]/lib/libLLVM*.so* 2>/dev/null | grep -q .; }
if have_llvm; then
  echo "setup: LLVM >= 16 found"
elif [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then
  echo "setup: installing libllvm19 (Dr.Jit's LLVM backend needs LLVM >= 16)"
  apt-get update -qq >/dev/null 2>&1
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libllvm19 >/dev/null 2>&1 \
    || echo "setup: warning: could not install libllvm19; Mitsuba will use scalar variants"
else
  echo "setup: warning: no LLVM >= 16 and no root/apt; Mitsuba will use scalar variants"
fi
exit 0
