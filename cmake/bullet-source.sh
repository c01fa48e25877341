# Sourced by the CI scripts that build Bullet from source (cmake/ci-source-bullet.sh, cmake/ci-cross.sh): Bullet 3.24
# from Debian's source package (apt-get source; its upstream tarball, without Debian's patches, as a user building a
# Bullet release has it), and the options of a library-only build (no extras, demos, tests or Bullet 3).
#   quathinge_bullet_source WORKDIR   downloads the tarball into WORKDIR/dl once (adds a deb-src line if there is
#                                     none, as root or through sudo), unpacks it afresh and sets bullet_src
#   bullet_options                    the library-only options (an array)
bullet_options=(-DCMAKE_BUILD_TYPE=Release -DBUILD_EXTRAS=OFF -DBUILD_UNIT_TESTS=OFF -DBUILD_CPU_DEMOS=OFF
  -DBUILD_BULLET2_DEMOS=OFF -DBUILD_OPENGL3_DEMOS=OFF -DBUILD_PYBULLET=OFF -DBUILD_BULLET3=OFF)

quathinge_bullet_source() {
  local work=$1 orig
  local as_root=()
  [ "$(id -u)" -eq 0 ] || as_root=(sudo)
  if ! ls "$work"/dl/bullet_*.orig.tar.* >/dev/null 2>&1; then
    if ! apt-get source --print-uris bullet >/dev/null 2>&1; then
      echo "adding deb-src for bookworm main"
      printf 'Types: deb-src\nURIs: http://deb.debian.org/debian\nSuites: bookworm\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' |
        "${as_root[@]}" tee /etc/apt/sources.list.d/quathinge-deb-src.sources >/dev/null
      "${as_root[@]}" apt-get update -qq
    fi
    mkdir -p "$work/dl"
    (cd "$work/dl" && apt-get source --download-only -qq bullet 2>&1 | grep -v "^W: Download is performed unsandboxed" || true)
  fi
  orig=$(ls "$work"/dl/bullet_*.orig.tar.* | head -n1)
  rm -rf "$work"/bullet3-*
  tar xf "$orig" -C "$work"
  bullet_src=$(ls -d "$work"/bullet3-* | head -n1)
  echo "source: $orig -> $bullet_src"
}

# build_bullet NAME [CMAKE OPTIONS...]: configures $bullet_src with bullet_options and the options given, builds it
# (-j2) and installs it into $work/bullet-NAME, once: an installed one (its bullet.pc) is reused within a run. Logs in
# $work/bullet-NAME.log.
build_bullet() {
  local name=$1; shift
  if [ -f "$work/bullet-$name/lib/pkgconfig/bullet.pc" ]; then echo "reusing $work/bullet-$name"; return; fi
  cmake -S "$bullet_src" -B "$work/bullet-build-$name" "${bullet_options[@]}" "$@" \
    -DCMAKE_INSTALL_PREFIX="$work/bullet-$name" >"$work/bullet-$name.log" 2>&1 || { cat "$work/bullet-$name.log"; exit 1; }
  cmake --build "$work/bullet-build-$name" -j2 >>"$work/bullet-$name.log" 2>&1 || { tail -n 30 "$work/bullet-$name.log"; exit 1; }
  cmake --install "$work/bullet-build-$name" >>"$work/bullet-$name.log"
  echo "installed: $(cd "$work/bullet-$name" && ls lib/*.a lib/pkgconfig/*.pc lib/cmake/bullet/BulletConfig.cmake | tr '\n' ' ')"
}
