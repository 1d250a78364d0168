#!/usr/bin/env python3
"""UDP round trips between two hosts, to measure a link (tests/fault/two_hosts.sh --delay).

    udp_rtt.py serve PORT            echo every datagram back to its sender (until killed)
    udp_rtt.py ping HOST PORT [N]    N round trips of 64 B, 20 ms apart (default 20)

ping prints one line: "udp_rtt: N round trips to HOST:PORT, min A ms, median B ms, max C ms, lost L"
(a datagram not answered within 2 s is lost). Exit 0 when at least one came back, 1 otherwise.
ICMP ping is not on every machine, and the link faults of two_hosts.sh touch UDP only.
"""
import socket
import statistics
import sys
import time


def serve(port):
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.bind(("0.0.0.0", port))
    while True:
        data, peer = s.recvfrom(2048)
        s.sendto(data, peer)


def one_round_trip(s, addr, seq):
    payload = seq.to_bytes(4, "big") + bytes(60)
    start = time.monotonic()
    s.sendto(payload, addr)
    while True:
        try:
            data, _ = s.recvfrom(2048)
        except socket.timeout:
            return None
        if data[:4] == payload[:4]:  # a late answer to an earlier datagram is skipped
            return (time.monotonic() - start) * 1000.0


def ping(host, port, n):
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    s.settimeout(2.0)
    rtts = []
    for seq in range(n):
        rtt = one_round_trip(s, (host, port), seq)
        if rtt is not None:
            rtts.append(rtt)
        time.sleep(0.02)
    if not rtts:
        print(f"udp_rtt: no answer from {host}:{port} in {n} tries")
        return 1
    print(f"udp_rtt: {len(rtts)} round trips to {host}:{port}, min {min(rtts):.2f} ms, "
          f"median {statistics.median(rtts):.2f} ms, max {max(rtts):.2f} ms, lost {n - len(rtts)}")
    return 0


def main(argv):
    try:
        if len(argv) == 3 and argv[1] == "serve":
            serve(int(argv[2]))
        elif len(argv) in (4, 5) and argv[1] == "ping":
            return ping(argv[2], int(argv[3]), int(argv[4]) if len(argv) == 5 else 20)
    except ValueError as e:
        print(f"udp_rtt: {e}", file=sys.stderr)
        return 30
    print(__doc__, file=sys.stderr)
    return 30


if __name__ == "__main__":
    sys.exit(main(sys.argv))
