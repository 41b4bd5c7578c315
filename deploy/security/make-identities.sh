#!/usr/bin/env bash
# Makes what a secured run needs (DDS Security, PKI-DH + access control + encryption; docs/runtime.md#security):
# a CA, an identity (certificate and private key) per process, and the governance and permissions documents,
# each signed by the CA (openssl from Debian), with a manifest saying what the folder is for.
#
# Usage: deploy/security/make-identities.sh --out DIR --agents N [--domain D] [--reuse] [--days D]
#   --domain D   the DDS domain (0..230) the folder is for: governance and permissions name it alone, so DDS itself
#                refuses these identities on any other domain (default: every domain 0..230)
#   --reuse      made on first use, kept afterwards: a DIR made before is reused when its manifest fits (the same
#                --domain, at least N agent identities, not expired), else refused (one line, exit 2, nothing
#                written); without --reuse an existing DIR is refused unless it is empty (never overwritten)
#   DIR/manifest                       domain, agents, CA sha256 fingerprint, created at, valid until (UTC)
#   DIR/ca.pem, ca.key                 the CA (identity CA and permissions CA at once)
#   DIR/world.pem|.key                 subject CN=marsala-world
#   DIR/monitor.pem|.key               subject CN=marsala-monitor
#   DIR/agent-K.pem|.key (K = 1..N)    subject CN=marsala-agent-K
#   DIR/governance.xml|.p7s            no unauthenticated participant; discovery, liveliness, RTPS messages and data
#                                      encrypted; read and write access control on every topic
#   DIR/permissions.xml|.p7s           what each subject may publish and subscribe (below)
# Private keys are 0600, the folder 0700 (ca.key signs new identities: keep it, or the whole folder, secret).
# Grants: the world publishes frames, admissions, status and events and subscribes to hellos, requests and status;
# the monitor subscribes to status and events; agent K publishes hellos, and requests only in the partitions of
# agent K's sessions (*/agent-K-*), and subscribes to admissions, status, and frames only in those partitions.
# The folder is made beside DIR and renamed into place: an interrupted run leaves no half folder.
# Prints one line: "identities: made DIR ..." or "identities: reusing DIR ...". Exit 2: bad usage or a DIR that does
# not fit; 1: openssl failed.
set -euo pipefail
out="" agents="" days=3650 domain="" reuse=0
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out="$2"; shift 2 ;;
    --agents) agents="$2"; shift 2 ;;
    --days) days="$2"; shift 2 ;;
    --domain) domain="$2"; shift 2 ;;
    --reuse) reuse=1; shift ;;
    -h|--help) awk 'NR > 1 && !/^#/ { exit } NR > 1 { sub(/^# ?/, ""); print }' "$0"; exit 0 ;;
    *) echo "make-identities.sh: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
done
[ -n "$out" ] || { echo "make-identities.sh: --out DIR is required" >&2; exit 2; }
[[ "$agents" =~ ^[0-9]+$ ]] && [ "$agents" -ge 1 ] ||
  { echo "make-identities.sh: --agents N (N >= 1) is required, got '$agents'" >&2; exit 2; }
[[ "$days" =~ ^[0-9]+$ ]] && [ "$days" -ge 1 ] || { echo "make-identities.sh: --days D (D >= 1), got '$days'" >&2; exit 2; }
[ -z "$domain" ] || { [[ "$domain" =~ ^[0-9]+$ ]] && [ "$domain" -le 230 ]; } ||
  { echo "make-identities.sh: --domain D must be 0..230 (Cyclone's access control reads no higher id)," \
      "got '$domain'" >&2; exit 2; }
command -v openssl >/dev/null || { echo "make-identities.sh: openssl not found (apt-get install openssl)" >&2; exit 1; }
wanted_domain="${domain:-0-230}"

manifest_field() { sed -n "s/^$1=//p" "$2/manifest" | head -1; }  # manifest_field NAME DIR
ca_fingerprint() { openssl x509 -noout -fingerprint -sha256 -in "$1/ca.pem" | sed 's/^.*=//'; }

# A folder made before: reused when it fits this run, refused (naming it and what does not fit) otherwise.
if [ -e "$out" ] && [ -n "$(ls -A "$out" 2>/dev/null)" ]; then
  if [ "$reuse" -eq 0 ]; then
    echo "make-identities.sh: $out exists and is not empty; give an empty or new folder (or --reuse to keep it)" >&2
    exit 2
  fi
  [ -f "$out/manifest" ] || {
    echo "make-identities.sh: $out is not an identity folder (no manifest): give another folder" >&2; exit 2; }
  have_domain=$(manifest_field domain "$out") have_agents=$(manifest_field agents "$out")
  have_ca=$(manifest_field ca_sha256 "$out") valid_until=$(manifest_field valid_until "$out")
  if [ "$have_domain" != "$wanted_domain" ] && [ "$have_domain" != 0-230 ]; then  # a folder for every domain fits any
    echo "make-identities.sh: $out was made for domain $have_domain, not $wanted_domain:" \
      "give that domain or another folder" >&2
    exit 2
  fi
  if ! [[ "$have_agents" =~ ^[0-9]+$ ]] || [ "$have_agents" -lt "$agents" ]; then
    echo "make-identities.sh: $out was made for $have_agents agents, this run needs $agents: give another folder" >&2
    exit 2
  fi
  if [ "$(ca_fingerprint "$out" 2>/dev/null)" != "$have_ca" ]; then
    echo "make-identities.sh: $out/ca.pem is not the CA its manifest names (sha256 $have_ca): give another folder" >&2
    exit 2
  fi
  if [ "$(date -u -d "$valid_until" +%s 2>/dev/null || echo 0)" -le "$(date -u +%s)" ]; then
    echo "make-identities.sh: $out expired at $valid_until: give another folder" >&2
    exit 2
  fi
  echo "identities: reusing $out (domain $have_domain, $have_agents agents, CA sha256 ${have_ca:0:23}...)"
  exit 0
fi

umask 077
parent="$(dirname "$out")"
mkdir -p "$parent"
parent="$(cd "$parent" && pwd)"  # absolute: the work below happens in another folder (a relative --out broke it)
work="$(mktemp -d "$parent/.identities.XXXXXX")"
final="$parent/$(basename "$out")"
trap 'rm -rf "$work"' EXIT
cd "$work"
log="$work/openssl.log"
ssl() {
  openssl "$@" >>openssl.log 2>&1 || { echo "make-identities.sh: openssl $1 failed: $(tail -1 "$log")" >&2; exit 1; }
}

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
if [ -n "$domain" ]; then
  domains="<domains><id>$domain</id></domains>"
else
  domains="<domains><id_range><min>0</min><max>230</max></id_range></domains>"
fi

cat >governance.xml <<EOF
<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"
     xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      $domains
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
        $domains
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
fingerprint=$(ca_fingerprint "$work")
cat >manifest <<EOF
# MARSala DDS Security identities (deploy/security/make-identities.sh; docs/runtime.md#security)
domain=$wanted_domain
agents=$agents
ca_sha256=$fingerprint
created_at=$(date -u +%Y-%m-%dT%H:%M:%SZ)
valid_until=${not_after}Z
EOF
rm -f ca.srl openssl.log
chmod 600 ./*.key
chmod 644 ./*.pem ./*.xml ./*.p7s manifest
chmod 700 "$work"
# Into place: DIR is new or empty (checked above).
[ -d "$final" ] && rmdir "$final"
mv "$work" "$final"
trap - EXIT
echo "identities: made $out for domain $wanted_domain, $agents agents (CA sha256 ${fingerprint:0:23}...)"
