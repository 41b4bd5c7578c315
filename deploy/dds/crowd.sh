# The crowd's timing for Fast DDS, one rule for every launcher: deploy/spawn.sh and bench/multihost_bench.sh source it
# from this folder, docker/entrypoint.sh from the folder of the profile it is given (the image holds this folder at
# /usr/local/share/marsala/dds). From marsala_crowd_agents agents on, a team's Fast DDS processes take the crowd twin
# of the shipped loopback and unicast profiles (heartbeats and announcements ten times as slow: README "Idle robots up
# to 120", "240 robots over four hosts"); Cyclone needs no other timing.

# The smallest team measured bad with fastdds-lo.xml (72-261 ms a step at 48 idle agents against 15-21 ms).
marsala_crowd_agents=48

# marsala_crowd_profile FILE AGENTS: the profile a Fast DDS process of a team of AGENTS takes for the profile FILE:
# the crowd twin beside it (fastdds-lo.xml -> fastdds-crowd.xml, fastdds-unicast.xml -> fastdds-unicast-crowd.xml)
# from marsala_crowd_agents agents on, when that twin is there; FILE otherwise (a user's own profile, another one).
marsala_crowd_profile() {
  local file=$1 agents=$2 dir twin=
  dir=$(dirname -- "$file")
  if [ "$agents" -ge "$marsala_crowd_agents" ]; then
    case "${file##*/}" in
      fastdds-lo.xml) twin=fastdds-crowd.xml ;;
      fastdds-unicast.xml) twin=fastdds-unicast-crowd.xml ;;
    esac
  fi
  if [ -n "$twin" ] && [ -f "$dir/$twin" ]; then echo "$dir/$twin"; else echo "$file"; fi
}
