#!/usr/bin/env bash
# Opens lcm-spy on masa's LCM traffic, with masa's message types decoded.
#
#   scripts/lcm_spy.sh [URL]     URL defaults to udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608
#
# Debian's /usr/bin/lcm-spy does not start on Java 17 (it passes -Xincgc) and lacks jchart2d on
# its class path, so this runs lcm.spy.Spy directly. It needs a JRE, liblcm-java, libjchart2d-java
# (scripts/install_deps.sh) and build/lcmtypes/masa_lcmtypes.jar, which it builds when missing.
set -euo pipefail
cd "$(dirname "$0")/.."

URL="${1:-udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608}"
BUILD_DIR="${MASA_BUILD_DIR:-build}"
JAR="$BUILD_DIR/lcmtypes/masa_lcmtypes.jar"
LCM_JAR=/usr/share/java/lcm.jar
JCHART_JAR=/usr/share/java/jchart2d.jar

die() { echo "lcm_spy.sh: $*" >&2; exit 1; }

command -v java >/dev/null || die "java not found: install a JRE (sudo apt-get install default-jre-headless, or run scripts/install_deps.sh)"
[[ -f "$LCM_JAR" ]] || die "$LCM_JAR missing: sudo apt-get install liblcm-java"
[[ -f "$JCHART_JAR" ]] || die "$JCHART_JAR missing: sudo apt-get install libjchart2d-java"

if [[ ! -f "$JAR" || -n "$(find lcmtypes -name '*.lcm' -newer "$JAR" 2>/dev/null)" ]]; then
  echo "lcm_spy.sh: building $JAR" >&2
  if [[ ! -f "$BUILD_DIR/CMakeCache.txt" ]]; then
    cmake -S . -B "$BUILD_DIR" -DCMAKE_BUILD_TYPE=Release >/dev/null
  fi
  cmake --build "$BUILD_DIR" --target masa_lcmtypes_jar >/dev/null ||
    die "could not build $JAR (needs javac and jar: sudo apt-get install default-jdk-headless)"
fi
[[ -f "$JAR" ]] || die "$JAR missing after the build: is javac installed (default-jdk-headless)?"

exec java -Djava.net.preferIPv4Stack=true -cp "$LCM_JAR:$JCHART_JAR:$JAR" lcm.spy.Spy -l "$URL"
