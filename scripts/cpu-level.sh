# Sourced by the scripts before they build. The build targets x86-64-v3 on x86-64
# (.cargo/config.toml); on an x86-64 CPU that lacks one of its instructions, the build would
# stop with SIGILL in a build script, so this builds for the baseline x86-64 instead (slower,
# the same output bytes). A RUSTFLAGS already set is left as it is.
if [ "$(uname -m)" = "x86_64" ] && [ -z "${RUSTFLAGS+set}" ]; then
  xbandsim_flags=""
  xbandsim_needed=""
  if [ -r /proc/cpuinfo ]; then
    # (No flags line, as under an emulator on another architecture: all count as missing.)
    xbandsim_flags=" $(grep -m1 '^flags' /proc/cpuinfo 2>/dev/null | cut -d: -f2 || true) "
    xbandsim_needed="avx avx2 bmi1 bmi2 f16c fma abm movbe xsave"
  elif [ "$(uname -s)" = "Darwin" ]; then
    xbandsim_flags=" $(sysctl -n machdep.cpu.features machdep.cpu.leaf7_features \
      machdep.cpu.extfeatures 2>/dev/null | tr '\n' ' ' || true) "
    xbandsim_needed="AVX1.0 AVX2 BMI1 BMI2 F16C FMA LZCNT MOVBE"
  fi
  xbandsim_missing=""
  for f in $xbandsim_needed; do
    case "$xbandsim_flags" in *" $f "*) ;; *) xbandsim_missing="$xbandsim_missing $f" ;; esac
  done
  if [ -n "$xbandsim_missing" ]; then
    echo "xbandsim: this CPU lacks x86-64-v3 (no$xbandsim_missing): building for the baseline x86-64, about 4 % slower" >&2
    export RUSTFLAGS="-C target-cpu=x86-64"
  fi
  unset f xbandsim_flags xbandsim_needed xbandsim_missing
fi
