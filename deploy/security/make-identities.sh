#!/usr/bin/env bash
# Makes what a secured run needs (DDS Security, PKI-DH + access control + encryption; docs/runtime.md#security):
# a CA, an identity (certificate and private key) per process, and the governance and permissions documents,
# each signed by the CA (openssl from Debian).
#
# Usage: deploy/security/make-identities.sh --out DIR --agents N [--days D]
#   DIR/ca.pem, ca.key                 the CA (identity CA and permissions CA at once)
#   DIR/world.pem|.key                 subject CN=marsala-world
#   DIR/monitor.pem|.key               subject CN=marsala-monitor
#   DIR/agent-K.pem|.key (K = 1..N)    subject CN=marsala-agent-K
#   DIR/governance.xml|.p7s            domains 0..230 (Cyclone's access control reads no higher id): no
#                                      unauthenticated participant; discovery, liveliness, RTPS messages and data
#                                      encrypted; read and write access control on every topic
#   DIR/permissions.xml|.p7s           what each subject may publish and subscribe (below)
# Grants: the world publishes frames, admissions, status and events and subscribes to hellos, requests and status;
# the monitor subscribes to status and events; agent K publishes hellos, and requests only in the partitions of
# agent K's sessions (*/agent-K-*), and subscribes to admissions, status, and frames only in those partitions.
# An existing DIR is refused unless it is empty (identities are not overwritten by accident).
set -euo pipefail
out="" agents="" days=3650
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out="$2"; shift 2 ;;
    --agents) agents="$2"; shift 2 ;;
    --days) days="$2"; shift 2 ;;
    -h|--help) sed -n '2,18p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "make-identities.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
done
[ -n "$out" ] || { echo "make-identities.sh: --out DIR is required" >&2; exit 2; }
[[ "$agents" =~ ^[0-9]+$ ]] && [ "$agents" -ge 1 ] ||
  { echo "make-identities.sh: --agents N (N >= 1) is required, got '$agents'" >&2; exit 2; }
[[ "$days" =~ ^[0-9]+$ ]] && [ "$days" -ge 1 ] || { echo "make-identities.sh: --days D (D >= 1), got '$days'" >&2; exit 2; }
command -v openssl >/dev/null || { echo "make-identities.sh: openssl not found (apt-get install openssl)" >&2; exit 1; }
if [ -e "$out" ] && [ -n "$(ls -A "$out" 2>/dev/null)" ]; then
  echo "make-identities.sh: $out exists and is not empty; give an empty or new folder" >&2
  exit 2
fi
mkdir -p "$out"
cd "$out"
log="$out/openssl.log"
ssl() { openssl "$@" >>openssl.log 2>&1 || { echo "make-identities.sh: openssl $1 failed (see $log)" >&2; exit 1; }; }

ssl req -x509 -newkey rsa:2048 -nodes -days "$days" -keyout ca.key -out ca.pem -subj "/CN=marsala-ca"
identity() {  # identity FILE_STEM COMMON_NAME
  ssl req -newkey rsa:2048 -nodes -keyout "$1.key" -out "$1.csr" -subj "/CN=$2"
  ssl x509 -req -days "$days" -in "$1.csr" -CA ca.pem -CAkey ca.key -CAcreateserial -out "$1.pem"
  rm -f "$1.csr"
}
identity world marsala-world
identity monitor marsala-monitor
for k in $(seq 1 "$agents"); do identity "agent-$k" "marsala-agent-$k"; done

# Validity of the grants: from yesterday (clocks a little apart) for --days.
not_before=$(date -u -d "yesterday" +%Y-%m-%dT%H:%M:%S)
not_after=$(date -u -d "+$days days" +%Y-%m-%dT%H:%M:%S)

cat >governance.xml <<'EOF'
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains><id_range><min>0</min><max>230</max></id_range></domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>ENCRYPT</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
EOF

grant() {  # grant NAME RULES_XML
  cat <<EOF
    <grant name="$1">
      <subject_name>CN=$1</subject_name>
      <validity><not_before>$not_before</not_before><not_after>$not_after</not_after></validity>
      <allow_rule>
        <domains><id_range><min>0</min><max>230</max></id_range></domains>
$2
      </allow_rule>
      <default>DENY</default>
    </grant>
EOF
}
topics() { for t in "$@"; do printf '<topic>marsala_%s</topic>' "$t"; done; }
{
  echo '<?xml version="1.0" encoding="UTF-8"?>'
  echo '<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"'
  echo '     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_permissions.xsd">'
  echo '  <permissions>'
  grant marsala-world "        <publish><topics>$(topics Admission WorldStatus WorldEvent)</topics></publish>
        <publish><topics>$(topics SensorFrame)</topics><partitions><partition>*/agent-*</partition></partitions></publish>
        <subscribe><topics>$(topics AgentHello WorldStatus)</topics></subscribe>
        <subscribe><topics>$(topics ActionRequest)</topics><partitions><partition>*/agent-*</partition></partitions></subscribe>"
  grant marsala-monitor "        <subscribe><topics>$(topics WorldStatus WorldEvent)</topics></subscribe>"
  for k in $(seq 1 "$agents"); do
    grant "marsala-agent-$k" "        <publish><topics>$(topics AgentHello)</topics></publish>
        <publish><topics>$(topics ActionRequest)</topics><partitions><partition>*/agent-$k-*</partition></partitions></publish>
        <subscribe><topics>$(topics Admission WorldStatus)</topics></subscribe>
        <subscribe><topics>$(topics SensorFrame)</topics><partitions><partition>*/agent-$k-*</partition></partitions></subscribe>"
  done
  echo '  </permissions>'
  echo '</dds>'
} >permissions.xml

ssl smime -sign -text -in governance.xml -out governance.p7s -signer ca.pem -inkey ca.key
ssl smime -sign -text -in permissions.xml -out permissions.p7s -signer ca.pem -inkey ca.key
rm -f ca.srl openssl.log
echo "identities for the world, the monitor and $agents agents in $out"
