#!/usr/bin/python3
"""Container HEALTHCHECK: grpc.health.v1 Check of inbetween-server (Debian has no grpc_health_probe)

Usage: healthcheck.py [HOST:PORT] [SERVICE]   (defaults: 127.0.0.1:50051, inbetween.v1.Inbetween)
Calls grpc.health.v1.Health/Check over plaintext and exits 0 when the answer is SERVING, 1
otherwise (NOT_SERVING while the server drains after SIGTERM, an unknown service, no answer
within 3 s). Needs only Debian's python3-grpcio: the two one-field messages are encoded by hand.
"""
import sys

import grpc

SERVING = 1  # grpc.health.v1.HealthCheckResponse.ServingStatus


def main() -> int:
    target = sys.argv[1] if len(sys.argv) > 1 else "127.0.0.1:50051"
    service = (sys.argv[2] if len(sys.argv) > 2 else "inbetween.v1.Inbetween").encode()
    if len(service) > 127:
        print("healthcheck: service name too long", file=sys.stderr)
        return 2
    request = b"\x0a" + bytes([len(service)]) + service  # HealthCheckRequest{string service = 1}
    with grpc.insecure_channel(target) as channel:
        check = channel.unary_unary("/grpc.health.v1.Health/Check")
        try:
            reply = check(request, timeout=3)
        except grpc.RpcError as error:
            print(f"unhealthy: {error.code().name}: {error.details()}")
            return 1
    # HealthCheckResponse{ServingStatus status = 1}: field 1 varint, absent when UNKNOWN (0).
    status = reply[1] if len(reply) == 2 and reply[0] == 0x08 else 0
    print("SERVING" if status == SERVING else f"unhealthy: status {status}")
    return 0 if status == SERVING else 1


if __name__ == "__main__":
    sys.exit(main())
