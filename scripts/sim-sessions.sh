# Sourced by the benchmark scripts from the project's root: the build tree,
# the set of simulated drives they judge a change on, and the session of
# each, simulated once and reused.
#   DRIVE = scene:platform:seconds:seed[:OPTIONS], e.g. mine:robot:60:3 (adit sim's options), or
#   mine:drone:60:1:--ground-s=2 or mine:drone:30:1:--sensor=Mid-360,--imu-on-can (OPTIONS: more of adit sim's
#   options, comma-separated; they name the session too; the sensor is the VLP-16 unless they give one)
# ADIT_BUILD_DIR: the build tree whose bin/ runs and which holds the sessions (default: build).
build=$(realpath "${ADIT_BUILD_DIR:-build}")

# The twelve drives of docs/decisions/014-judge-map-on-twelve-drives.md.
default_drives=(mine:robot:12:7 mine:robot:60:1 mine:robot:60:2 mine:robot:60:3 mine:robot:60:4 mine:robot:60:5
                mine:robot:60:6 mine:robot:60:7 mine:robot:120:11 drift:robot:150:1 drift:robot:90:2 drift:robot:90:3)

# use_drives RUNS_NAME [DRIVE ...]: sets `drives` to the drives given, or the
# twelve, and `runs` to the folder $build/RUNS_NAME for the runs' files.
use_drives() {
  runs=$build/$1
  mkdir -p "$runs"
  shift
  drives=("$@")
  [ ${#drives[@]} -gt 0 ] || drives=("${default_drives[@]}")
}

# sim_session DRIVE LOG_DIR: prints the session folder, simulating it first
# when it is not there yet (the log goes to LOG_DIR/NAME-sim.log).
sim_session() {
  local scene platform seconds seed options name session
  IFS=: read -r scene platform seconds seed options <<< "$1"
  if [ -z "$seed" ]; then
    echo "$1: expected scene:platform:seconds:seed[:OPTIONS]" >&2
    return 2
  fi
  name="$scene-$platform-$seconds-s$seed"
  local -a more=()
  if [ -n "$options" ]; then
    IFS=, read -r -a more <<< "$options"
    name="$name-$(printf '%s' "$options" | tr -c 'A-Za-z0-9.' '-' | sed -e 's/--*/-/g' -e 's/^-//')"
  fi
  local -a sensor=(--sensor VLP-16)
  [[ ",$options" != *,--sensor* ]] || sensor=()
  session="$build/sessions/bench-map/$name"
  if [ ! -f "$session/lidar.pcap" ]; then
    mkdir -p "$2"
    "$build/bin/adit" sim --scene "$scene" --platform "$platform" "${sensor[@]}" --duration "$seconds" --seed "$seed" \
      "${more[@]}" --out "$session" > "$2/$name-sim.log" 2>&1 || { echo "$1: adit sim failed ($2/$name-sim.log)" >&2; return 1; }
  fi
  echo "$session"
}

# aditd_config SESSION WORK [REPLAY_SPEED [PCAP [CAN_LOG]]]: prints aditd's
# configuration for a simulated session: the simulator's own session.yaml with
# absolute paths, WORK/state as the state folder, the replay pace (default 0:
# as fast as it goes; a replay waits for each stage, so nothing is dropped) and
# the recordings to replay (default: the session's own).
aditd_config() {
  local session=$1 work=$2 speed=${3:-0} pcap=${4:-$1/lidar.pcap} can=${5:-$1/can.log}
  sed -e "s#  state_dir: state#  state_dir: $work/state#" \
      -e "s#  pcap: lidar.pcap#  pcap: $pcap#" \
      -e "s#  calibration: VLP16.yaml#  calibration: $session/VLP16.yaml#" \
      -e "s#  log: can.log#  log: $can#" \
      -e "s#  replay_speed: 1.0#  replay_speed: $speed#" "$session/session.yaml"
  printf 'threads:\n  lock_memory: false\n'
}

# map_once SESSION WORK [EXTRA_YAML [REPLAY_SPEED]]: aditd maps the session once
# (`--once`; as fast as it goes unless REPLAY_SPEED is given: 1 = the drive's own
# pace) into WORK, reused while WORK/done exists; the benchmark makes its own
# products, so aditd makes none. Prints the session folder aditd wrote.
map_once() {
  local session=$1 work=$2 extra=${3:-} speed=${4:-0}
  if [ ! -f "$work/done" ]; then
    rm -rf "$work"
    mkdir -p "$work"
    aditd_config "$session" "$work" "$speed" > "$work/aditd.yaml"
    printf 'session:\n  products: false\n' >> "$work/aditd.yaml"
    [ -z "$extra" ] || printf '%s\n' "$extra" >> "$work/aditd.yaml"
    "$build/bin/aditd" --config "$work/aditd.yaml" --once > "$work/aditd.log" 2>&1 ||
      { echo "$session: aditd failed ($work/aditd.log)" >&2; return 1; }
    touch "$work/done"
  fi
  ls -d "$work"/state/sessions/*/ | head -1
}
