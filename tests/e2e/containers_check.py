#!/usr/bin/python3
"""Checks docker/ and deploy/k8s/ without a container engine (driven by containers_test.sh).

Usage: containers_check.py --src SRC --bin BUILD_DIR --work DIR [--k8s RENDERED]
Static checks of docker/Dockerfile, docker/compose.yaml, docker/runtime-packages.txt and the
rendered `kubectl kustomize deploy/k8s` (RENDERED), then their commands run for real on loopback:
Redis as compose (docker/redis-entrypoint.sh) and Kubernetes (its shell command) start it, with a
password from a secret file and maxmemory/noeviction, the servers with the compose and Kubernetes
flags on it (tokens on), the nginx entrypoint in front of them, the HEALTHCHECK scripts and
inbetween-loadgen with the compose arguments (its token from the secret file). Secrets: the
password is in no process's argv, none is committed. Every failure is listed; exit 1 if there is
any. Needs Debian's python3-yaml and python3-grpcio (/usr/bin/python3), apt-cache, dpkg, ldd,
nginx, haproxy, node, redis-server and redis-cli; git for the committed-secrets checks.
"""
import argparse
import fnmatch
import json
import os
import re
import shlex
import shutil
import socket
import subprocess
import sys
import time

import yaml

HEALTH_SERVICE = "inbetween.v1.Inbetween"
FAILURES = []


def check(ok, message):
    if not ok:
        FAILURES.append(message)
        print(f"FAIL: {message}", file=sys.stderr)
    return bool(ok)


def run(cmd, **kw):
    return subprocess.run(cmd, capture_output=True, text=True, **kw)


def help_flags(cmd):
    """The --long-flags a program's --help lists."""
    out = run(cmd + ["--help"])
    return set(re.findall(r"(--[a-z][a-z0-9-]*)", out.stdout + out.stderr)) - {"--help"}


def gateway_options(main_mjs):
    """The gateway's flags, from its parseArgs options in main.mjs (running it needs the npm
    packages, which tests/e2e/web_test.sh may be installing at the same time)."""
    source = open(main_mjs).read()
    block = re.search(r"parseArgs\(\{\s*options:\s*\{(.*?)\n\s*\},\s*\}\)", source, re.S)
    keys = re.findall(
        r'^\s*"?([a-z][a-z-]*)"?:\s*\{\s*type:', block.group(1) if block else "", re.M
    )
    return {f"--{k}" for k in keys} - {"--help"}


def flags_of(args):
    return [a.split("=", 1)[0] for a in args if isinstance(a, str) and a.startswith("--")]


def flag_value(args, flag):
    for i, a in enumerate(args):
        if a == flag and i + 1 < len(args):
            return args[i + 1]
    return None


def with_value(args, flag, value):
    """args with FLAG's value replaced (or FLAG VALUE appended)."""
    out = list(args)
    for i, a in enumerate(out):
        if a == flag:
            out[i + 1] = value
            return out
    return out + [flag, value]


def port_of(hostport):
    return int(hostport.rsplit(":", 1)[1])


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Processes:
    """Started processes, killed on exit."""

    def __init__(self, work):
        self.work, self.procs = work, []

    def start(self, name, cmd, env=None):
        log = open(os.path.join(self.work, f"{name}.log"), "w")
        proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, env=env)
        proc.log_path = log.name
        self.procs.append(proc)
        return proc

    def stop_all(self):
        for p in reversed(self.procs):
            if p.poll() is None:
                p.terminate()  # nginx's master stops its workers on SIGTERM
                try:
                    p.wait(timeout=10)
                except subprocess.TimeoutExpired:
                    p.kill()


def log_of(proc):
    with open(proc.log_path) as f:
        return f.read()


def start_server(procs, server_bin, name, args):
    """inbetween-server with ARGS; returns its loopback address or None."""
    proc = procs.start(name, [server_bin] + args)
    for _ in range(400):
        m = re.search(r"inbetween-server listening on (127\.0\.0\.1:\d+)", log_of(proc))
        if m:
            return m.group(1)
        if proc.poll() is not None:
            break
        time.sleep(0.05)
    check(False, f"{name}: inbetween-server {shlex.join(args)} did not start:\n{log_of(proc)}")
    return None


def wait_port(proc, port):
    for _ in range(200):
        if proc.poll() is not None:
            return False
        try:
            socket.create_connection(("127.0.0.1", port), timeout=0.2).close()
            return True
        except OSError:
            time.sleep(0.05)
    return False


def healthcheck(src, addr, service=HEALTH_SERVICE):
    out = run(
        ["/usr/bin/python3", os.path.join(src, "docker/healthcheck.py"), addr, service], timeout=30
    )
    return out.returncode, (out.stdout + out.stderr).strip()


def check_health_answers(src):
    """healthcheck.py against a fake grpc.health.v1 server answering each status (the real server
    rejects new calls once it drains, so it never shows NOT_SERVING to a new connection)."""
    import grpc
    from concurrent import futures

    answer = {}
    server = grpc.server(futures.ThreadPoolExecutor(max_workers=2))
    server.add_generic_rpc_handlers(
        [
            grpc.method_handlers_generic_handler(
                "grpc.health.v1.Health",
                {
                    "Check": grpc.unary_unary_rpc_method_handler(
                        lambda request, context: answer["reply"]
                    )
                },
            )
        ]
    )
    port = server.add_insecure_port("127.0.0.1:0")
    server.start()
    try:
        for reply, want in ((b"\x08\x01", 0), (b"\x08\x02", 1), (b"", 1), (b"\x08\x03", 1)):
            answer[
                "reply"
            ] = reply  # HealthCheckResponse: SERVING, NOT_SERVING, UNKNOWN, SERVICE_UNKNOWN
            rc, out = healthcheck(src, f"127.0.0.1:{port}")
            check(rc == want, f"healthcheck.py exits {rc} for the reply {reply!r}: {out}")
    finally:
        server.stop(0)


# ------------------------------------------------------------------------ secrets and Redis


def k8s_expand(text, env):
    """Kubernetes' expansion of a container's command and args: $(NAME) of a defined variable
    becomes its value, $$ becomes $, anything else stays as it is (the kubelet's
    third_party/forked/golang/expansion)."""
    out, i = [], 0
    while i < len(text):
        if text[i] == "$" and i + 1 < len(text):
            if text[i + 1] == "$":
                out.append("$")
                i += 2
                continue
            end = text.find(")", i + 2) if text[i + 1] == "(" else -1
            if end != -1:
                name = text[i + 2 : end]
                out.append(str(env[name]) if name in env else text[i : end + 1])
                i = end + 1
                continue
            out.append(text[i : i + 2])
            i += 2
            continue
        out.append(text[i])
        i += 1
    return "".join(out)


def redis_bytes(value):
    """Redis' memory size (1gb, 512mb, 100000000) in bytes, or None."""
    m = re.fullmatch(r"(\d+)(k|kb|m|mb|g|gb)?", str(value or "").lower())
    units = {None: 1, "k": 1000, "kb": 1024, "m": 10**6, "mb": 1024**2, "g": 10**9, "gb": 1024**3}
    return int(m.group(1)) * units[m.group(2)] if m else None


def sample_secrets():
    """Values for the secrets of the local runs: a password Redis' configuration must quote (a
    space, a double quote, a backslash), and a bearer token."""
    import secrets

    return f'pass word "{secrets.token_hex(6)}" back\\slash', f"tok-{secrets.token_urlsafe(16)}"


def write_file(path, text):
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as f:
        f.write(text)
    return path


def redis_cli(port, *args, password=None):
    """redis-cli's answer on 127.0.0.1:PORT; the password goes through REDISCLI_AUTH."""
    env = {k: v for k, v in os.environ.items() if k != "REDISCLI_AUTH"}
    if password is not None:
        env["REDISCLI_AUTH"] = password
    out = run(["redis-cli", "-h", "127.0.0.1", "-p", str(port)] + list(args), env=env, timeout=10)
    return (out.stdout + out.stderr).replace("\r", "").strip()


def start_redis(procs, work, name, make_cmd, password, env=None):
    """MAKE_CMD(port) (an entrypoint or shell that execs redis-server) on a free loopback port,
    another one if that port was taken. Returns (port, argv file) once Redis answers with
    PASSWORD and reports the started process's pid (the exec kept it), else (None, None).
    redis-server replaces its argv with a title once it runs, so `redis-server` is found first
    in a directory where a script records the arguments it gets (NUL-separated, in the argv
    file) and execs the real one."""
    real = shutil.which("redis-server")
    spy = write_file(os.path.join(work, "redis-argv/redis-server"),
                     f'#!/bin/sh\nprintf \'%s\\0\' "$@" >"$INBETWEEN_REDIS_ARGV"\n'
                     f'exec {shlex.quote(real)} "$@"\n')
    os.chmod(spy, 0o755)
    argv_file = os.path.join(work, f"{name}.argv")
    env = dict(env or os.environ, INBETWEEN_REDIS_ARGV=argv_file,
               PATH=os.path.dirname(spy) + os.pathsep + os.environ.get("PATH", ""))
    proc = None
    for _ in range(5):
        port = free_port()
        proc = procs.start(name, make_cmd(port), env=env)
        for _ in range(200):
            if proc.poll() is not None or redis_cli(port, "ping", password=password) == "PONG":
                break
            time.sleep(0.05)
        if f"process_id:{proc.pid}" in redis_cli(port, "info", "server", password=password):
            return port, argv_file
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    check(False, f"{name}: Redis did not start (or not as the started process):\n{log_of(proc)}")
    return None, None


def argv_holding(secret):
    """The pids whose command line contains SECRET (any user can read every process's argv)."""
    needle, found = secret.encode(), []
    for pid in os.listdir("/proc"):
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                if pid.isdigit() and needle in f.read():
                    found.append(int(pid))
        except OSError:
            pass
    return found


def check_redis_secured(name, port, password, maxmemory, argv_file):
    """Redis on PORT refuses clients without PASSWORD, has maxmemory MAXMEMORY (Redis' notation)
    with noeviction; redis-server got its configuration from stdin (ARGV_FILE: its arguments)
    and the password is in no process's argv."""
    with open(argv_file, "rb") as f:
        argv = f.read().split(b"\0")
    check(argv[:1] == [b"-"], f"{name}: redis-server's first argument is not - (stdin): {argv}")
    check(
        password.encode() not in b" ".join(argv), f"{name}: redis-server got the password in argv"
    )
    reply = redis_cli(port, "ping")
    check(reply.startswith("NOAUTH"), f"{name}: PING without a password answered {reply!r}")
    reply = redis_cli(port, "ping", password=password + "x")
    check(reply != "PONG", f"{name}: a wrong password was accepted")
    words = redis_cli(port, "config", "get", "maxmemory*", password=password).split("\n")
    conf = dict(zip(words[::2], words[1::2]))
    check(
        redis_bytes(maxmemory)
        and conf.get("maxmemory") == str(redis_bytes(maxmemory))
        and conf.get("maxmemory-policy") == "noeviction",
        f"{name}: not maxmemory {maxmemory} with noeviction: {conf}",
    )
    holders = argv_holding(password)
    check(not holders, f"{name}: the Redis password is in the command line of pids {holders}")


def call_status(addr, token=None, method="ListSessions"):
    """(gRPC code, serialized status details) of METHOD with an empty request on ADDR, with the
    bearer TOKEN if any. An empty ListSessions reads the store, an empty CreateSession writes."""
    import grpc

    with grpc.insecure_channel(addr) as channel:
        call = channel.unary_unary(f"/{HEALTH_SERVICE}/{method}")
        metadata = [("authorization", f"Bearer {token}")] if token else None
        try:
            call(b"", metadata=metadata, timeout=20)
            return "OK", b""
        except grpc.RpcError as e:
            details = dict(e.trailing_metadata() or ()).get("grpc-status-details-bin", b"")
            return e.code().name, details


def call_code(addr, token=None):
    return call_status(addr, token)[0]


def check_tokens_required(name, addr, token):
    """Tokens on: a call without one is refused; with TOKEN it passes and reaches Redis."""
    code = call_code(addr)
    check(code == "UNAUTHENTICATED", f"{name}: a call without a token got {code}")
    code = call_code(addr, token)
    check(code == "OK", f"{name}: ListSessions with the token got {code} (Redis AUTH?)")


def check_secrets_not_committed(src, files):
    """No secret value in git: nothing under docker/secrets/ is tracked but its .gitignore, the
    compose secrets' FILES are ignored, and no tracked manifest is a Kubernetes Secret."""
    inside = run(["git", "-C", src, "rev-parse", "--is-inside-work-tree"])
    if inside.returncode != 0 or inside.stdout.strip() != "true":
        print("secrets: the source is not a git work tree; the git checks are skipped")
        return
    tracked = run(["git", "-C", src, "ls-files", "docker/secrets"]).stdout.split()
    check(
        set(tracked) <= {"docker/secrets/.gitignore"},
        f"files under docker/secrets/ are in git: {tracked}",
    )
    for name, path in files.items():
        rel = os.path.relpath(path, src)
        check(
            run(["git", "-C", src, "check-ignore", "-q", rel]).returncode == 0,
            f"compose secret {name}: {rel} is not git-ignored",
        )
    for rel in run(["git", "-C", src, "ls-files", "deploy", "docker"]).stdout.split():
        if rel.endswith((".yaml", ".yml")) and os.path.exists(os.path.join(src, rel)):
            with open(os.path.join(src, rel)) as f:
                kinds = [d.get("kind") for d in yaml.safe_load_all(f) if isinstance(d, dict)]
            check("Secret" not in kinds, f"{rel} is a Kubernetes Secret (its value is in git)")
    print(f"secrets: {len(files)} compose secrets git-ignored, no Secret manifest in git")


# ---------------------------------------------------------------------------- Dockerfile


def parse_dockerfile(path):
    """[(stage name, base, [(INSTRUCTION, text)])] with continuation lines joined; the global
    ARGs (before the first FROM) are in GLOBAL_ARGS, {name: default}."""
    lines, current = [], ""
    for raw in open(path):
        line = raw.rstrip("\n")
        if not current and (not line.strip() or line.lstrip().startswith("#")):
            continue
        if current and line.lstrip().startswith("#"):
            continue  # a comment inside a continued instruction
        if line.endswith("\\"):
            current += line[:-1] + " "
            continue
        lines.append(current + line)
        current = ""
    stages = []
    GLOBAL_ARGS.clear()
    for line in lines:
        word, _, rest = line.strip().partition(" ")
        word, rest = word.upper(), rest.strip()
        if word == "ARG" and not stages:
            name, _, default = rest.partition("=")
            GLOBAL_ARGS[name.strip()] = default.strip().strip('"')
        elif word == "FROM":
            parts = rest.split()
            name = parts[2] if len(parts) >= 3 and parts[1].upper() == "AS" else str(len(stages))
            stages.append((name, parts[0], []))
        elif stages:
            stages[-1][2].append((word, rest))
    return stages


GLOBAL_ARGS = {}


def resolve(base):
    """A FROM's image with the global ARGs' defaults: ${BASE_IMAGE} -> debian:bookworm-slim."""
    return re.sub(r"\$\{(\w+)\}|\$(\w+)", lambda m: GLOBAL_ARGS.get(m.group(1) or m.group(2), ""),
                  base)


def exec_form(text):
    try:
        value = json.loads(text)
        return value if isinstance(value, list) else None
    except json.JSONDecodeError:
        return None


def copy_parts(text):
    """COPY [--from=X] [--chown..] SRC... DEST -> (from, [src], dest)."""
    parts = shlex.split(text)
    opts = [p for p in parts if p.startswith("--")]
    rest = [p for p in parts if not p.startswith("--")]
    source = next((o.split("=", 1)[1] for o in opts if o.startswith("--from=")), None)
    return source, rest[:-1], rest[-1]


def dockerignored(patterns, path):
    """Whether PATH (relative to the context) or one of its parents matches .dockerignore."""
    parts = path.strip("/").split("/")
    prefixes = ["/".join(parts[: i + 1]) for i in range(len(parts))]
    ignored = False
    for pattern in patterns:
        negate = pattern.startswith("!")
        p = pattern.lstrip("!").strip("/")
        for prefix in prefixes:
            if fnmatch.fnmatch(prefix, p) or (
                p.startswith("**/")
                and (fnmatch.fnmatch(prefix, p[3:]) or fnmatch.fnmatch(prefix, "*/" + p[3:]))
            ):
                ignored = not negate
    return ignored


def check_dockerfile(src, bin_dir, server_flags, gateway_flags):
    path = os.path.join(src, "docker/Dockerfile")
    stages = parse_dockerfile(path)
    by_name = {name: (base, instrs) for name, base, instrs in stages}
    ignore = [
        l.strip()
        for l in open(os.path.join(src, ".dockerignore"))
        if l.strip() and not l.startswith("#")
    ]
    for d in ("build", "build/test", "build-server", "out", "client/web/node_modules",
              "docker/secrets"):
        check(dockerignored(ignore, d), f".dockerignore does not exclude {d}/ from the context")

    # Sources copied from the context exist and are not excluded by .dockerignore.
    for name, _, instrs in stages:
        for word, text in instrs:
            if word in ("COPY", "ADD"):
                source, srcs, _ = copy_parts(text)
                for s in srcs if source is None else []:
                    if s == ".":
                        continue
                    check(
                        os.path.exists(os.path.join(src, s)),
                        f"Dockerfile {name}: COPY {s} is missing",
                    )
                    check(
                        not dockerignored(ignore, s),
                        f"Dockerfile {name}: COPY {s} is in .dockerignore",
                    )

    # One base: every stage is FROM ${BASE_IMAGE} (Debian 12 by default; scripts/containers
    # passes a local one) or FROM an earlier stage.
    check(
        GLOBAL_ARGS.get("BASE_IMAGE") == "debian:bookworm-slim",
        "docker/Dockerfile has no global `ARG BASE_IMAGE=debian:bookworm-slim`",
    )
    seen = set()
    for name, base, _ in stages:
        check(
            base == "${BASE_IMAGE}" or resolve(base) in seen,
            f"Dockerfile stage {name} is FROM {base}, not ${{BASE_IMAGE}} or an earlier stage",
        )
        seen.add(name)
    # build: the first stage, runs exactly the scripts CI runs.
    check(stages and stages[0][0] == "build", "the first stage is not `build`")
    base, instrs = by_name.get("build", ("", []))
    commands = []
    for word, text in instrs:
        if word == "RUN":
            text = re.sub(r"^(--\S+\s+)+", "", text)
            commands += [c.strip() for c in text.split("&&")]
    check(
        commands == ["scripts/setup", "scripts/build build/release Release ${BUILD_ARGS}"],
        f"the build stage's RUN steps are {commands}, not exactly scripts/setup and scripts/build",
    )
    ci = open(os.path.join(src, ".ci/run")).read()
    test_script = open(os.path.join(src, "scripts/test")).read()
    check(
        "scripts/test" in ci
        and '"$root/scripts/setup"' in test_script
        and '"$root/scripts/build"' in test_script,
        "CI (.ci/run -> scripts/test) no longer runs scripts/setup and scripts/build",
    )
    workdir = next((t for w, t in instrs if w == "WORKDIR"), "/")
    # COPY --from=binaries: by default (BINARIES=build) the build stage.
    binaries = {
        n for n, b, _ in stages if n == "build" or (b.startswith("$") and resolve(b) == "build")
    }
    check(len(binaries) == 2, "no stage `FROM ${BINARIES}` with BINARIES=build by default")
    build_prefix = os.path.join(workdir, "build/release") + "/"

    # web-build runs the script tests/e2e/web_test.sh runs.
    _, web = by_name.get("web-build", ("", []))
    check(
        any(w == "RUN" and "client/web/scripts/prepare.sh" in t for w, t in web),
        "the web-build stage does not run client/web/scripts/prepare.sh",
    )
    check(
        "scripts/prepare.sh" in open(os.path.join(src, "tests/e2e/web_test.sh")).read(),
        "tests/e2e/web_test.sh no longer runs client/web/scripts/prepare.sh",
    )
    web_generated = open(os.path.join(src, "client/web/.gitignore")).read().split()

    images = {}
    for name in ("server", "gateway", "proxy", "redis"):
        if not check(name in by_name, f"Dockerfile has no stage {name}"):
            continue
        base, instrs = by_name[name]
        users = [t for w, t in instrs if w == "USER"]
        check(
            users and users[-1].split(":")[0] not in ("root", "0"),
            f"stage {name} does not end as a non-root USER",
        )
        copies = {}
        for w, t in instrs:
            if w == "COPY":
                source, srcs, dest = copy_parts(t)
                for s in srcs:
                    copies[dest if len(srcs) == 1 else os.path.join(dest, os.path.basename(s))] = (
                        source,
                        s,
                    )
                    if source in binaries:
                        check(
                            s.startswith(build_prefix)
                            and os.access(os.path.join(bin_dir, s[len(build_prefix) :]), os.X_OK),
                            f"stage {name}: COPY --from={source} {s} is not a binary "
                            f"scripts/build makes "
                            f"(under {build_prefix})",
                        )
                    if source == "web-build":
                        rel = os.path.relpath(s, "/src/client/web")
                        check(
                            os.path.exists(os.path.join(src, "client/web", rel))
                            or rel + "/" in web_generated,
                            f"stage {name}: COPY --from=web-build {s} is neither in client/web "
                            f"nor one of its generated directories",
                        )
        expose = {int(p.split("/")[0]) for w, t in instrs if w == "EXPOSE" for p in t.split()}
        entry = next((exec_form(t) for w, t in reversed(instrs) if w == "ENTRYPOINT"), None)
        cmd = next((exec_form(t) for w, t in reversed(instrs) if w == "CMD"), None) or []
        health = next((t for w, t in reversed(instrs) if w == "HEALTHCHECK"), None)
        check(entry, f"stage {name} has no exec-form ENTRYPOINT")
        images[name] = dict(
            base=base,
            copies=copies,
            expose=expose,
            entry=entry or [],
            cmd=cmd,
            health=health,
            instrs=instrs,
        )

    server = images.get("server")
    if server:
        pk = [
            d
            for d, (s, f) in server["copies"].items()
            if s is None and f == "docker/runtime-packages.txt"
        ]
        check(
            pk
            and any(
                w == "RUN" and pk[0] in t and "apt-get install" in t for w, t in server["instrs"]
            ),
            "the server stage does not apt-get install the packages of docker/runtime-packages.txt",
        )
        check(
            server["entry"][:1] == ["/usr/local/bin/inbetween-server"]
            or server["entry"][:1] == ["inbetween-server"],
            "the server image's ENTRYPOINT is not inbetween-server",
        )
        check(
            set(flags_of(server["cmd"])) <= server_flags,
            f"the server image's CMD has flags inbetween-server does not know: {server['cmd']}",
        )
        for flag in ("--listen", "--metrics-listen"):
            value = flag_value(server["cmd"], flag)
            check(
                value and port_of(value) in server["expose"],
                f"the server image does not EXPOSE its {flag} port",
            )
        hc = exec_form(re.sub(r"^.*?\bCMD\s+", "", server["health"] or "")) or []
        check(
            hc
            and server["copies"].get(
                os.path.join("/usr/local/bin", hc[0]) if "/" not in hc[0] else hc[0], (None, "")
            )[1]
            == "docker/healthcheck.py",
            f"the server HEALTHCHECK does not run docker/healthcheck.py: {server['health']}",
        )
        check(
            len(hc) >= 2
            and port_of(hc[1]) == port_of(flag_value(server["cmd"], "--listen") or ":0"),
            "the server HEALTHCHECK does not check the port of the default --listen",
        )
        check(
            len(hc) < 3 or hc[2] == HEALTH_SERVICE,
            f"the HEALTHCHECK's service is not {HEALTH_SERVICE}",
        )
    gateway = images.get("gateway")
    if gateway:
        check(
            any(
                w == "RUN" and re.search(r"apt-get install .*\bnodejs\b", t)
                for w, t in gateway["instrs"]
            ),
            "the gateway stage does not install Debian's nodejs",
        )
        check(
            set(flags_of(gateway["cmd"])) <= gateway_flags,
            f"the gateway image's CMD has unknown flags: {gateway['cmd']}",
        )
    proxy = images.get("proxy")
    if proxy:
        entry_script = open(os.path.join(src, "docker/nginx-entrypoint.sh")).read()
        template = re.search(r"INBETWEEN_NGINX_TEMPLATE:-([^}]+)}", entry_script).group(1)
        check(
            proxy["copies"].get(template, (None, ""))[1] == "deploy/nginx/inbetween.conf",
            f"the proxy image does not put deploy/nginx/inbetween.conf at {template}",
        )
        check(
            any(
                w == "RUN" and re.search(r"apt-get install .*\bnginx\b.*\bhaproxy\b", t)
                for w, t in proxy["instrs"]
            ),
            "the proxy stage does not install nginx and haproxy",
        )
    redis = images.get("redis")
    if redis:
        # The password: the entrypoint script feeds it to redis-server on stdin, the health check
        # authenticates; maxmemory with noeviction by default.
        def copied(image, command):
            path = command if "/" in command else os.path.join("/usr/local/bin", command)
            return image["copies"].get(path, (None, ""))[1]

        check(
            redis["entry"][:1] and copied(redis, redis["entry"][0]) == "docker/redis-entrypoint.sh",
            f"the redis image's ENTRYPOINT is not docker/redis-entrypoint.sh: {redis['entry']}",
        )
        hc = exec_form(re.sub(r"^.*?\bCMD\s+", "", redis["health"] or "")) or []
        check(
            hc and copied(redis, hc[0]) == "docker/redis-healthcheck.sh",
            f"the redis HEALTHCHECK is not docker/redis-healthcheck.sh: {redis['health']}",
        )
        check(
            redis_bytes(flag_value(redis["cmd"], "--maxmemory"))
            and flag_value(redis["cmd"], "--maxmemory-policy") == "noeviction",
            f"the redis image's CMD has no --maxmemory with noeviction: {redis['cmd']}",
        )
    return images


# ------------------------------------------------------------------------ runtime packages


def dpkg_owners(paths):
    """{path: package} for the PATHS dpkg knows (one `dpkg -S` call; usrmerge: a library that
    ldd finds in /lib may be registered under /usr/lib or the other way round)."""
    candidates = {}
    for path in paths:
        for c in (path, os.path.realpath(path)):
            other = (
                c[4:] if c.startswith("/usr/lib/") else "/usr" + c if c.startswith("/lib") else c
            )
            candidates.setdefault(path, []).extend([c, other])
    owners = {}
    out = run(["dpkg", "-S"] + sorted({c for cs in candidates.values() for c in cs}))
    for line in out.stdout.splitlines():
        pkgs, sep, owned = line.rpartition(": ")
        if sep and not line.startswith("diversion"):
            owners[owned.strip()] = pkgs.split(",")[0].split(":")[0].strip()
    return {p: next((owners[c] for c in cs if c in owners), None) for p, cs in candidates.items()}


def check_runtime_packages(src, binaries):
    listed = []
    for line in open(os.path.join(src, "docker/runtime-packages.txt")):
        listed += line.split("#", 1)[0].split()
    check(len(listed) == len(set(listed)), "docker/runtime-packages.txt repeats a package")
    if not check(
        run(["apt-cache", "show", "libc6"]).returncode == 0,
        "apt-cache knows no packages (empty package lists: run apt-get update)",
    ):
        return
    out = run(["apt-cache", "show", "--no-all-versions"] + listed)
    known = set(re.findall(r"^Package: (\S+)$", out.stdout, re.M))
    for pkg in listed:
        check(pkg in known, f"runtime package {pkg} is not in Debian (apt-cache show)")
    check(
        "python3-grpcio" in listed, "docker/runtime-packages.txt lacks python3-grpcio (HEALTHCHECK)"
    )
    libs = {}
    for binary in binaries:
        out = run(["ldd", binary])
        check(out.returncode == 0, f"ldd {binary} failed")
        if re.search(r"lib(asan|tsan)\.so", out.stdout):
            # scripts/sanitize's builds link the sanitizer runtimes (and more libraries directly);
            # the image ships release binaries, whose libraries are what the list must cover.
            print(f"runtime packages: {binary} is a sanitizer build, ldd check skipped")
            return
        for line in out.stdout.splitlines():
            check("not found" not in line, f"{binary}: {line.strip()}")
            m = re.search(r"=>\s+(/\S+)", line) or re.match(r"\s*(/\S+)", line)
            if m:
                libs.setdefault(m.group(1), set()).add(os.path.basename(binary))
    needed = {}
    for lib, pkg in dpkg_owners(libs).items():
        if check(
            pkg, f"{lib} (needed by {', '.join(sorted(libs[lib]))}) belongs to no Debian package"
        ):
            needed.setdefault(pkg, set()).add(os.path.basename(lib))
    for pkg, names in sorted(needed.items()):
        check(
            pkg in listed, f"docker/runtime-packages.txt lacks {pkg} ({', '.join(sorted(names))})"
        )
    print(
        f"runtime packages: {len(listed)} listed, {len(needed)} needed by ldd ({len(libs)} "
        f"libraries), all present"
    )


# ---------------------------------------------------------------------------------- compose


def check_compose(src, images, server_flags, loadgen_flags, gateway_flags):
    compose = yaml.safe_load(open(os.path.join(src, "docker/compose.yaml")))
    services = compose.get("services", {})
    stages = {"server", "gateway", "proxy", "redis"}
    for name, svc in services.items():
        build = svc.get("build")
        if build:
            context = os.path.normpath(os.path.join(src, "docker", build.get("context", ".")))
            check(
                context == os.path.normpath(src),
                f"compose {name}: build context is not the repository root",
            )
            check(
                os.path.join(context, build.get("dockerfile", "Dockerfile"))
                == os.path.join(src, "docker/Dockerfile"),
                f"compose {name}: not built from docker/Dockerfile",
            )
            check(
                build.get("target") in stages,
                f"compose {name}: unknown build target {build.get('target')}",
            )
            check(
                (build.get("args") or {}).get("BASE_IMAGE") == "${BASE_IMAGE:-debian:bookworm-slim}",
                f"compose {name}: build argument BASE_IMAGE is not "
                "${BASE_IMAGE:-debian:bookworm-slim}",
            )
        for dep in svc.get("depends_on", {}) or {}:
            check(dep in services, f"compose {name}: depends_on unknown service {dep}")
    for want in ("redis", "nginx", "gateway", "loadgen"):
        check(want in services, f"compose has no service {want}")
    redis = services.get("redis", {})
    check(
        (redis.get("build") or {}).get("target") == "redis" and redis.get("healthcheck"),
        "compose redis: not the redis image of docker/Dockerfile with a healthcheck",
    )

    def target(svc):
        return (svc.get("build") or {}).get("target")

    # Secrets: compose's top-level file secrets under docker/secrets/ (git-ignored, outside the
    # build context), mounted at /run/secrets/NAME; never a value in a command or environment.
    secret_files = {}
    for name in ("redis_password", "tokens"):
        file = ((compose.get("secrets") or {}).get(name) or {}).get("file")
        path = os.path.normpath(os.path.join(src, "docker", file or "."))
        check(
            file and os.path.dirname(path) == os.path.join(src, "docker/secrets"),
            f"compose: no top-level secret {name} with a file under docker/secrets/",
        )
        secret_files[name] = path

    def secrets_of(svc):
        return [r if isinstance(r, str) else r.get("source") for r in svc.get("secrets") or []]

    for name, svc in services.items():
        args = [str(x) for x in (svc.get("entrypoint") or []) + (svc.get("command") or [])]
        for a in args:
            if a.startswith("/run/secrets/"):
                check(
                    os.path.basename(a) in secrets_of(svc),
                    f"compose {name}: {a} is not one of its secrets {secrets_of(svc)}",
                )
        check(
            "--token" not in args and "--requirepass" not in args,
            f"compose {name}: a secret value in its command line: {args}",
        )
        for key in svc.get("environment") or {}:
            check(
                not re.search(r"PASSWORD|TOKEN|SECRET", key, re.I),
                f"compose {name}: environment {key} looks like a secret value",
            )

    # Redis: the image's entrypoint (password from the secret on stdin), an authenticating
    # health check, maxmemory with noeviction.
    rcmd = [str(x) for x in redis.get("command") or []]
    check(
        "redis_password" in secrets_of(redis) and not redis.get("entrypoint"),
        "compose redis: does not mount the secret redis_password for the image's entrypoint",
    )
    check(
        redis_bytes(flag_value(rcmd, "--maxmemory"))
        and flag_value(rcmd, "--maxmemory-policy") == "noeviction",
        f"compose redis: no --maxmemory with --maxmemory-policy noeviction: {rcmd}",
    )
    rtest = [str(x) for x in (redis.get("healthcheck") or {}).get("test") or []]
    redis_copies = images.get("redis", {}).get("copies", {})
    health_script = redis_copies.get(os.path.join("/usr/local/bin", rtest[1] if len(rtest) > 1
                                                  else ""), (None, ""))[1]
    check(
        rtest[:1] == ["CMD"] and health_script == "docker/redis-healthcheck.sh",
        f"compose redis: the healthcheck is not the image's authenticating PING: {rtest}",
    )

    replicas = {
        n: s
        for n, s in services.items()
        if target(s) == "server" and "load" not in (s.get("profiles") or [])
    }
    check(len(replicas) == 3, f"compose has {len(replicas)} inbetween-server replicas, not 3")
    for name, svc in replicas.items():
        args = svc.get("command") or []
        check(
            set(flags_of(args)) <= server_flags,
            f"compose {name}: unknown inbetween-server flags in {args}",
        )
        check(
            flag_value(args, "--store") == "redis://redis:6379",
            f"compose {name}: --store is not the redis service (redis://redis:6379)",
        )
        check(
            svc.get("depends_on", {}).get("redis", {}).get("condition") == "service_healthy",
            f"compose {name}: does not wait for a healthy redis",
        )
        check(
            flag_value(args, "--redis-password-file") == "/run/secrets/redis_password",
            f"compose {name}: no --redis-password-file /run/secrets/redis_password",
        )
        check(
            flag_value(args, "--tokens") == "/run/secrets/tokens",
            f"compose {name}: no --tokens /run/secrets/tokens (tokens are on by default)",
        )
        check(
            (flag_value(args, "--session-ttl-seconds") or "").isdigit(),
            f"compose {name}: no explicit --session-ttl-seconds",
        )

    nginx = services.get("nginx", {})
    env = nginx.get("environment", {})
    listed = env.get("INBETWEEN_REPLICAS", "").split()
    check(target(nginx) == "proxy", "compose nginx: not the proxy image")
    check(
        sorted(h.rsplit(":", 1)[0] for h in listed) == sorted(replicas),
        f"compose nginx: INBETWEEN_REPLICAS {listed} are not the replica services "
        f"{sorted(replicas)}",
    )
    for hostport in listed:
        rep = replicas.get(hostport.rsplit(":", 1)[0])
        if rep:
            check(
                port_of(hostport) == port_of(flag_value(rep["command"], "--listen") or ":0"),
                f"compose nginx: {hostport} is not that replica's --listen port",
            )
        check(
            nginx.get("depends_on", {}).get(hostport.rsplit(":", 1)[0], {}).get("condition")
            == "service_healthy",
            f"compose nginx: does not wait for {hostport} to be healthy",
        )
    proxy_port = int(str(env.get("INBETWEEN_PROXY_LISTEN", "0")).rsplit(":", 1)[-1])

    gateway = services.get("gateway", {})
    gargs = gateway.get("command") or []
    check(target(gateway) == "gateway", "compose gateway: not the gateway image")
    check(
        set(flags_of(gargs)) <= gateway_flags, f"compose gateway: unknown gateway flags in {gargs}"
    )
    check(
        flag_value(gargs, "--upstream") == f"nginx:{proxy_port}",
        f"compose gateway: --upstream is not nginx:{proxy_port}",
    )

    load = services.get("loadgen", {})
    check("load" in (load.get("profiles") or []), "compose loadgen: not under the `load` profile")
    check(
        target(load) == "server",
        "compose loadgen: not the server image (which has inbetween-loadgen)",
    )
    check(
        load.get("network_mode") == "service:nginx",
        "compose loadgen: not in nginx's network namespace (its target must be loopback)",
    )
    largs = (load.get("entrypoint") or [])[1:] + (load.get("command") or [])
    check(
        (load.get("entrypoint") or [""])[0]
        in ("inbetween-loadgen", "/usr/local/bin/inbetween-loadgen")
        and "/usr/local/bin/inbetween-loadgen" in images.get("server", {}).get("copies", {}),
        "compose loadgen: its entrypoint is not the image's inbetween-loadgen",
    )
    check(set(flags_of(largs)) <= loadgen_flags, f"compose loadgen: unknown flags in {largs}")
    check(
        flag_value(largs, "--token-file") == "/run/secrets/tokens",
        "compose loadgen: does not read its token from the secret "
        "(--token-file /run/secrets/tokens)",
    )
    tgt = flag_value(largs, "--target") or ":0"
    check(
        tgt.rsplit(":", 1)[0] in ("127.0.0.1", "localhost") and port_of(tgt) == proxy_port,
        f"compose loadgen: --target {tgt} is not nginx's port {proxy_port} on loopback",
    )
    examples_dest = next(
        (
            d
            for d, (s, f) in images.get("server", {}).get("copies", {}).items()
            if s is None and f == "examples"
        ),
        None,
    )
    drawings = []
    i = largs.index("--drawings") + 1 if "--drawings" in largs else len(largs)
    while i < len(largs) and not largs[i].startswith("--"):
        d = largs[i]
        local = (
            os.path.join(src, "examples", os.path.relpath(d, examples_dest))
            if examples_dest
            else ""
        )
        check(
            examples_dest and d.startswith(examples_dest + "/") and os.path.isfile(local),
            f"compose loadgen: drawing {d} is not a file the image copies from examples/",
        )
        drawings.append(local)
        i += 1
    return dict(
        replicas=replicas,
        listed=listed,
        proxy_port=proxy_port,
        loadgen_args=largs,
        drawings=drawings,
        secret_files=secret_files,
        redis_command=rcmd,
        redis_health=rtest,
    )


def run_compose_locally(src, bin_dir, procs, work, compose):
    """The compose services' commands on loopback: Redis through the image's entrypoint script
    with compose's command and a password file, replicas on it with their secrets, the proxy
    image's nginx entrypoint in front of them, the HEALTHCHECK scripts, inbetween-loadgen through
    nginx."""
    server_bin = os.path.join(bin_dir, "server/inbetween-server")
    password, token = sample_secrets()
    files = {
        "redis_password": write_file(os.path.join(work, "compose-secrets/redis_password"),
                                     password + "\n"),
        # A comment first: inbetween-loadgen --token-file skips it, as the server does.
        "tokens": write_file(os.path.join(work, "compose-secrets/tokens"),
                             f"# compose's tokens\n{token} compose\n"),
    }

    def local(args):
        """/run/secrets/NAME (compose's mounts) -> the test's file."""
        return [files.get(a[len("/run/secrets/"):], a) if a.startswith("/run/secrets/") else a
                for a in args]

    entry = os.path.join(src, "docker/redis-entrypoint.sh")
    health = [os.path.join(src, "docker/redis-healthcheck.sh")] + compose["redis_health"][2:]
    out = run([entry, "--port", str(free_port())], timeout=30,
              env=dict(os.environ, REDIS_PASSWORD_FILE=os.path.join(work, "no-such-file")))
    check(out.returncode != 0 and "password file" in out.stderr,
          f"docker/redis-entrypoint.sh started without a password file: {out.stderr}")
    env = dict(os.environ, REDIS_PASSWORD_FILE=files["redis_password"])
    rcmd = with_value(compose["redis_command"], "--dir", os.path.join(work, "compose-redis"))
    os.makedirs(os.path.join(work, "compose-redis"), exist_ok=True)
    redis_port, argv_file = start_redis(
        procs, work, "compose-redis",
        lambda p: [entry] + rcmd + ["--port", str(p), "--bind", "127.0.0.1", "--save", ""],
        password, env=env)
    if not redis_port:
        return
    check_redis_secured("compose redis", redis_port, password,
                        flag_value(compose["redis_command"], "--maxmemory"), argv_file)
    out = run(health[:1] + ["-p", str(redis_port)] + health[1:], env=env, timeout=30)
    check(out.returncode == 0, f"compose redis healthcheck: {out.stdout}{out.stderr}")
    wrong = write_file(os.path.join(work, "compose-secrets/wrong"), "not-the-password\n")
    out = run(health[:1] + ["-p", str(redis_port)] + health[1:], timeout=30,
              env=dict(os.environ, REDIS_PASSWORD_FILE=wrong))
    check(out.returncode != 0, "compose redis healthcheck passes with a wrong password")

    addrs = {}
    for name, svc in sorted(compose["replicas"].items()):
        args = with_value(local(svc["command"]), "--listen", "127.0.0.1:0")
        args = with_value(args, "--metrics-listen", "127.0.0.1:0")
        args = with_value(args, "--store", f"redis://127.0.0.1:{redis_port}")
        addrs[name] = start_server(procs, server_bin, f"compose-{name}", args)
    if not all(addrs.values()):
        return
    for name, addr in addrs.items():
        rc, out = healthcheck(src, addr)
        check(rc == 0, f"HEALTHCHECK against compose {name} ({addr}): {out}")
        check_tokens_required(f"compose {name}", addr, token)
    port = free_port()
    env = dict(
        os.environ,
        INBETWEEN_REPLICAS=" ".join(addrs[h.rsplit(":", 1)[0]] for h in compose["listed"]),
        INBETWEEN_PROXY_LISTEN=f"127.0.0.1:{port}",
        INBETWEEN_NGINX_TEMPLATE=os.path.join(src, "deploy/nginx/inbetween.conf"),
        INBETWEEN_NGINX_DIR=os.path.join(work, "nginx"),
        INBETWEEN_NGINX_WORKERS="1",
    )
    nginx = procs.start("compose-nginx", [os.path.join(src, "docker/nginx-entrypoint.sh")], env=env)
    if not check(
        wait_port(nginx, port), f"docker/nginx-entrypoint.sh did not start nginx:\n{log_of(nginx)}"
    ):
        return
    rendered = open(os.path.join(work, "nginx/inbetween.conf")).read()
    check(
        sorted(re.findall(r"^\s*server (127\.0\.0\.1:\d+) max_fails=", rendered, re.M))
        == sorted(addrs.values()),
        "the nginx entrypoint did not put the replicas into the upstream",
    )
    rc, out = healthcheck(src, f"127.0.0.1:{port}")
    check(rc == 0, f"HEALTHCHECK through the nginx entrypoint: {out}")
    check_tokens_required("compose nginx", f"127.0.0.1:{port}", token)
    holders = argv_holding(token)
    check(not holders, f"compose: the bearer token is in the command line of pids {holders}")

    # The load generator with the compose arguments: target nginx here, drawings from examples/,
    # a short bounded run.
    args = local(compose["loadgen_args"])
    args = with_value(args, "--target", f"127.0.0.1:{port}")
    i = args.index("--drawings") + 1
    for local in compose["drawings"]:
        args[i] = local
        i += 1
    args = with_value(with_value(args, "--seconds", "20"), "--max-requests", "80")
    report_path = os.path.join(work, "loadgen.json")
    out = run(
        [os.path.join(bin_dir, "tools/loadgen/inbetween-loadgen")] + args + ["--json", report_path],
        timeout=120,
    )
    if check(
        out.returncode == 0,
        f"inbetween-loadgen {shlex.join(args)}: exit {out.returncode}\n"
        f"{out.stdout}{out.stderr}",
    ):
        report = json.load(open(report_path))
        other = {
            k: v for k, v in report.get("errors_by_code", {}).items() if k != "RESOURCE_EXHAUSTED"
        }
        check(
            report.get("requests", 0) >= 80
            and not other
            and report.get("lost_sessions") == 0
            and report.get("streams_completed", 0) >= 1
            and report.get("frames_identical"),
            f"the compose load run through nginx: {json.dumps(report)[:600]}",
        )
        print(
            f"compose on loopback: Redis with a password and noeviction, 3 replicas with tokens, "
            f"nginx entrypoint, loadgen (--token-file) {report['requests']} requests, "
            f"{report['streams_completed']} streams, 0 lost"
        )

    # A full store as a client sees it: Redis at maxmemory with noeviction refuses a new session
    # (RESOURCE_EXHAUSTED, reason STORE_FULL in the status details), reads keep working.
    redis_cli(redis_port, "config", "set", "maxmemory", "1", password=password)
    code, details = call_status(f"127.0.0.1:{port}", token, "CreateSession")
    check(
        code == "RESOURCE_EXHAUSTED" and b"STORE_FULL" in details,
        f"compose: CreateSession on a full Redis got {code} {details!r}, not RESOURCE_EXHAUSTED "
        "with reason STORE_FULL",
    )
    code = call_code(f"127.0.0.1:{port}", token)
    if check(code == "OK", f"compose: ListSessions on a full Redis got {code}"):
        print("compose: a full Redis refuses CreateSession (RESOURCE_EXHAUSTED, STORE_FULL); "
              "ListSessions still answers")
    redis_cli(redis_port, "config", "set", "maxmemory",
              flag_value(compose["redis_command"], "--maxmemory"), password=password)


# ------------------------------------------------------------------------------- kubernetes


def labels_match(selector, labels):
    return bool(selector) and all(labels.get(k) == v for k, v in selector.items())


def secret_source(workload, container, path):
    """(Secret name, key) of the file PATH in CONTAINER of WORKLOAD, or None."""
    volumes = {v["name"]: v for v in workload["spec"]["template"]["spec"].get("volumes", [])}
    for m in container.get("volumeMounts", []):
        base = m["mountPath"].rstrip("/") + "/"
        secret = volumes.get(m["name"], {}).get("secret")
        if path.startswith(base) and secret:
            rel = path[len(base):]
            items = secret.get("items")
            key = next((i["key"] for i in items if i["path"] == rel), None) if items else rel
            return (secret.get("secretName"), key) if key else None
    return None


def local_secret_mounts(workload, container, values, local_dir):
    """{mountPath: a local directory} for CONTAINER's Secret volumes, each file written from
    VALUES (by key) as the kubelet would project it."""
    volumes = {v["name"]: v for v in workload["spec"]["template"]["spec"].get("volumes", [])}
    mounts = {}
    for m in container.get("volumeMounts", []):
        secret = volumes.get(m["name"], {}).get("secret")
        if secret:
            d = os.path.join(local_dir, m["name"])
            items = secret.get("items") or [{"key": k, "path": k} for k in values]
            for i in items:
                write_file(os.path.join(d, i["path"]), values.get(i["key"], ""))
            mounts[m["mountPath"].rstrip("/") + "/"] = d + "/"
    return mounts


def localized(text, mounts):
    for mount, d in mounts.items():
        text = text.replace(mount, d)
    return text


def check_k8s(src, bin_dir, procs, work, rendered, server_flags):
    docs = [d for d in yaml.safe_load_all(open(rendered)) if d]
    kinds = {}
    for d in docs:
        kinds.setdefault(d["kind"], []).append(d)
    configmaps = {d["metadata"]["name"]: d.get("data", {}) for d in kinds.get("ConfigMap", [])}
    services = kinds.get("Service", [])
    workloads = kinds.get("Deployment", []) + kinds.get("StatefulSet", [])

    def containers(w):
        return w["spec"]["template"]["spec"]["containers"]

    def image_of(w):
        return containers(w)[0]["image"]

    def pod_labels(w):
        return w["spec"]["template"]["metadata"].get("labels", {})

    def services_for(w):
        return [s for s in services if labels_match(s["spec"].get("selector"), pod_labels(w))]

    for w in workloads:
        name = w["metadata"]["name"]
        check(
            labels_match(w["spec"]["selector"]["matchLabels"], pod_labels(w)),
            f"{name}: its selector does not match its pods",
        )
        sc = w["spec"]["template"]["spec"].get("securityContext", {})
        for c in containers(w):
            limits = c.get("resources", {}).get("limits", {})
            check(
                "cpu" in limits and "memory" in limits,
                f"{name}/{c['name']}: no cpu and memory limits",
            )
            check(
                sc.get("runAsNonRoot") or c.get("securityContext", {}).get("runAsNonRoot"),
                f"{name}/{c['name']}: not runAsNonRoot",
            )
            for e in c.get("env", []):
                ref = e.get("valueFrom", {}).get("configMapKeyRef")
                if ref:
                    check(
                        ref["key"] in configmaps.get(ref["name"], {}),
                        f"{name}: env {e['name']} refers to missing ConfigMap key "
                        f"{ref['name']}/{ref['key']}",
                    )
        for v in w["spec"]["template"]["spec"].get("volumes", []):
            if "configMap" in v:
                check(
                    v["configMap"]["name"] in configmaps,
                    f"{name}: volume of missing ConfigMap {v['configMap']['name']}",
                )
        check(services_for(w), f"{name}: no Service selects its pods")

    servers = [w for w in kinds.get("Deployment", []) if image_of(w).startswith("inbetween-server")]
    if not check(len(servers) == 1, "not exactly one Deployment runs inbetween-server"):
        return
    deploy = servers[0]
    c = containers(deploy)[0]
    env = {}
    for e in c.get("env", []):
        ref = e.get("valueFrom", {}).get("configMapKeyRef")
        env[e["name"]] = configmaps.get(ref["name"], {}).get(ref["key"]) if ref else e.get("value")
    args = [k8s_expand(a, env) for a in c.get("args", [])]
    check(c["image"].startswith("inbetween-server:"), f"the server image has no tag: {c['image']}")
    check(not any("$(" in a for a in args), f"the server args have unresolved variables: {args}")
    check(
        set(flags_of(args)) <= server_flags,
        f"the server Deployment's args have unknown flags: {args}",
    )
    listen_port = port_of(flag_value(args, "--listen") or ":0")
    for probe in ("readinessProbe", "livenessProbe"):
        grpc = c.get(probe, {}).get("grpc", {})
        check(
            grpc.get("port") == listen_port and grpc.get("service") == HEALTH_SERVICE,
            f"server {probe} is not a grpc probe of {HEALTH_SERVICE} on port {listen_port}: "
            f"{c.get(probe)}",
        )
    limits = c["resources"]["limits"]
    cpus = float(str(limits["cpu"]).rstrip("m")) / (1000 if str(limits["cpu"]).endswith("m") else 1)
    heavy = int(flag_value(args, "--max-heavy-jobs") or 0)
    threads = int(flag_value(args, "--solver-threads") or 1)
    check(
        0 < heavy * threads <= max(1, round(cpus)),
        f"--max-heavy-jobs {heavy} x --solver-threads {threads} does not fit the CPU limit "
        f"{limits['cpu']}",
    )
    # No secret in the manifests (the operator creates inbetween-secrets); the servers read it.
    check(not kinds.get("Secret"), "the manifests hold a Secret: its value would be committed")
    check(
        "replicas" not in deploy["spec"],
        "the server Deployment sets replicas: every apply would reset its HPA's count",
    )
    for flag, key in (("--redis-password-file", "redis-password"), ("--tokens", "tokens")):
        path = flag_value(args, flag) or ""
        check(
            secret_source(deploy, c, path) == ("inbetween-secrets", key),
            f"the server's {flag} {path!r} is not the key {key} of the Secret inbetween-secrets",
        )
    raw_ttl = flag_value(c.get("args", []), "--session-ttl-seconds") or ""
    check(
        raw_ttl.startswith("$(") and (flag_value(args, "--session-ttl-seconds") or "").isdigit(),
        f"the server's --session-ttl-seconds is not a number from the ConfigMap: {raw_ttl!r}",
    )
    grace = int(flag_value(args, "--shutdown-grace-ms") or 5000) / 1000
    check(
        deploy["spec"]["template"]["spec"].get("terminationGracePeriodSeconds", 30) > grace,
        "terminationGracePeriodSeconds does not exceed --shutdown-grace-ms",
    )

    headless = [s for s in services_for(deploy) if s["spec"].get("clusterIP") == "None"]
    check(
        headless and any(p["port"] == listen_port for p in headless[0]["spec"]["ports"]),
        "no headless Service lists the server pods on the gRPC port",
    )
    hpas = [
        h
        for h in kinds.get("HorizontalPodAutoscaler", [])
        if h["spec"]["scaleTargetRef"]
        == {"apiVersion": "apps/v1", "kind": "Deployment", "name": deploy["metadata"]["name"]}
    ]
    pdbs = [
        p
        for p in kinds.get("PodDisruptionBudget", [])
        if labels_match(p["spec"]["selector"]["matchLabels"], pod_labels(deploy))
    ]
    if check(hpas, "no HorizontalPodAutoscaler scales the server Deployment"):
        hpa = hpas[0]["spec"]
        check(
            2 <= hpa["minReplicas"] <= hpa["maxReplicas"],
            f"HPA replicas {hpa['minReplicas']}..{hpa['maxReplicas']}",
        )
        if check(pdbs, "no PodDisruptionBudget covers the server pods"):
            check(
                0 < pdbs[0]["spec"].get("minAvailable", 0) < hpa["minReplicas"],
                "the PDB's minAvailable must be below the HPA's minReplicas (else drains block)",
            )

    # Redis: a workload on a redis image behind the Service that --store names.
    store = flag_value(args, "--store") or ""
    m = re.fullmatch(r"redis://([a-z0-9-]+):(\d+)", store)
    redis = [w for w in workloads if image_of(w).startswith("redis:")]
    redis_script = redis_probe = None
    if check(m and redis, f"--store {store} is not redis://SERVICE:PORT, or no Redis workload"):
        svc = [s for s in services_for(redis[0]) if s["metadata"]["name"] == m.group(1)]
        check(
            svc and any(p["port"] == int(m.group(2)) for p in svc[0]["spec"]["ports"]),
            f"--store {store}: no Service of that name and port selects the Redis pods",
        )
        # The password from the Secret on stdin (`redis-server -`, in a shell), maxmemory with
        # noeviction, a probe that authenticates.
        rc = containers(redis[0])[0]
        renv = {e["name"]: e.get("value", "") for e in rc.get("env", [])}
        rcmd = [k8s_expand(x, renv) for x in rc.get("command", []) + rc.get("args", [])]
        script = rcmd[2] if rcmd[:2] == ["sh", "-c"] and len(rcmd) == 3 else ""
        paths = set(re.findall(r"/run/[\w./-]+", script))
        check(
            "redis-server -" in script
            and re.search(r"^\s*requirepass ", script, re.M)
            and any(secret_source(redis[0], rc, p) == ("inbetween-secrets", "redis-password")
                    for p in paths),
            f"Redis does not get requirepass on stdin from the Secret's redis-password: {rcmd}",
        )
        maxmemory = re.search(r"--maxmemory (\S+)", script)
        check(
            maxmemory and redis_bytes(maxmemory.group(1))
            and re.search(r"--maxmemory-policy noeviction\b", script),
            f"Redis has no --maxmemory with --maxmemory-policy noeviction: {script}",
        )
        probe = (rc.get("readinessProbe") or {}).get("exec", {}).get("command") or []
        check(
            "REDISCLI_AUTH" in " ".join(probe)
            and any(secret_source(redis[0], rc, p) == ("inbetween-secrets", "redis-password")
                    for p in re.findall(r"/run/[\w./-]+", " ".join(probe))),
            f"Redis' readinessProbe does not authenticate with the Secret: {probe}",
        )
        if script and maxmemory:
            redis_script, redis_probe = script, probe

    # The proxy: HAProxy from the proxy image with the generated ConfigMap.
    proxies = [w for w in kinds.get("Deployment", []) if image_of(w).startswith("inbetween-proxy")]
    haproxy_cfg = None
    if check(len(proxies) == 1, "not exactly one Deployment runs the proxy image"):
        p = containers(proxies[0])[0]
        cmd = p.get("command", [])
        cfg_path = flag_value(cmd, "-f") or ""
        mounts = {m["mountPath"]: m["name"] for m in p.get("volumeMounts", [])}
        vols = {v["name"]: v for v in proxies[0]["spec"]["template"]["spec"].get("volumes", [])}
        vol = vols.get(mounts.get(os.path.dirname(cfg_path)), {})
        data = configmaps.get(vol.get("configMap", {}).get("name"), {})
        check(
            cmd[:1] == ["haproxy"] and os.path.basename(cfg_path) in data,
            f"the proxy does not run haproxy -f on a mounted ConfigMap file: {cmd}",
        )
        haproxy_cfg = data.get(os.path.basename(cfg_path))
        check(
            haproxy_cfg == open(os.path.join(src, "deploy/k8s/haproxy.cfg")).read(),
            "the rendered HAProxy ConfigMap is not deploy/k8s/haproxy.cfg",
        )
        check("readinessProbe" in p, "the proxy has no readinessProbe")
        envs = {e["name"]: e for e in p.get("env", [])}
        check(
            envs.get("POD_NAMESPACE", {}).get("valueFrom", {}).get("fieldRef", {}).get("fieldPath")
            == "metadata.namespace",
            "the proxy does not get POD_NAMESPACE from the downward API",
        )
        pports = {cp["containerPort"] for cp in p.get("ports", [])}
        check(services_for(proxies[0]), "no Service for the proxy")
    if haproxy_cfg:
        check_haproxy_k8s(
            src,
            work,
            haproxy_cfg,
            headless,
            listen_port,
            pports,
            hpas[0]["spec"]["maxReplicas"] if hpas else 0,
        )

    # Redis' command, run for real: the shell script with the Secret's file projected into a
    # local directory (a password that needs quoting), on a free port; its probe.
    password, token = sample_secrets()
    values = {"redis-password": password + "\n", "tokens": f"{token} k8s\n"}
    redis_port = None
    if redis_script:
        rc = containers(redis[0])[0]
        mounts = local_secret_mounts(redis[0], rc, values, os.path.join(work, "k8s-redis-secrets"))
        data = os.path.join(work, "k8s-redis-data")
        os.makedirs(data, exist_ok=True)
        script = localized(redis_script, mounts).replace(" --dir /data", f" --dir {data}")
        redis_port, argv_file = start_redis(
            procs, work, "k8s-redis",
            lambda p: ["sh", "-c", script.replace(
                "redis-server -", f"redis-server - --port {p} --bind 127.0.0.1 --save ''", 1)],
            password)
    if redis_port:
        check_redis_secured("k8s redis", redis_port, password,
                            re.search(r"--maxmemory (\S+)", redis_script).group(1), argv_file)
        probe = [localized(x, mounts).replace("redis-cli ", f"redis-cli -p {redis_port} ", 1)
                 for x in redis_probe]
        out = run(probe, timeout=30)
        check(out.returncode == 0, f"Redis' readinessProbe fails: {out.stdout}{out.stderr}")
        wrong = local_secret_mounts(redis[0], rc, {"redis-password": "wrong\n"},
                                    os.path.join(work, "k8s-wrong-secrets"))
        out = run([localized(x, wrong).replace("redis-cli ", f"redis-cli -p {redis_port} ", 1)
                   for x in redis_probe], timeout=30)
        check(out.returncode != 0, "Redis' readinessProbe passes with a wrong password")

        # The Deployment's args, run for real: a server on that Redis with the Secret's files,
        # health as the probes ask, tokens required.
        mounts = local_secret_mounts(deploy, c, values, os.path.join(work, "k8s-server-secrets"))
        run_args = [localized(a, mounts) for a in args]
        run_args = with_value(run_args, "--listen", "127.0.0.1:0")
        run_args = with_value(run_args, "--metrics-listen", "127.0.0.1:0")
        run_args = with_value(run_args, "--store", f"redis://127.0.0.1:{redis_port}")
        addr = start_server(
            procs, os.path.join(bin_dir, "server/inbetween-server"), "k8s-server", run_args
        )
        if addr:
            rc_, out = healthcheck(src, addr, c["readinessProbe"]["grpc"]["service"])
            check(
                rc_ == 0,
                f"the Deployment's server does not answer its probe's health check: {out}",
            )
            check_tokens_required("the Deployment's server", addr, token)
    print(f"kubernetes: {', '.join(f'{k} {len(v)}' for k, v in sorted(kinds.items()))}")


def check_haproxy_k8s(src, work, cfg, headless, listen_port, proxy_ports, max_replicas):
    path = os.path.join(work, "haproxy-k8s.cfg")
    with open(path, "w") as f:
        f.write(cfg)
    out = run(["haproxy", "-c", "-f", path], env=dict(os.environ, POD_NAMESPACE="default"))
    check(
        out.returncode == 0, f"haproxy -c rejects deploy/k8s/haproxy.cfg:\n{out.stdout}{out.stderr}"
    )

    def settings(text):
        return {l.split("#")[0].strip() for l in text.splitlines() if l.split("#")[0].strip()}

    template = settings(open(os.path.join(src, "deploy/haproxy/inbetween.cfg")).read())
    ours = settings(cfg)
    shared = {l for l in template if not re.match(r"(server|bind) ", l)}
    check(
        shared <= ours, f"deploy/k8s/haproxy.cfg lacks template settings: {sorted(shared - ours)}"
    )
    m = re.search(r'^\s*server-template \S+ (\d+) "?([^"\s]+):(\d+)"? .*resolvers', cfg, re.M)
    if check(m, "deploy/k8s/haproxy.cfg has no server-template with resolvers"):
        check(
            headless
            and m.group(2).split(".")[0] == headless[0]["metadata"]["name"]
            and int(m.group(3)) == listen_port,
            f"the server-template {m.group(2)}:{m.group(3)} is not the headless Service's "
            "gRPC port",
        )
        check(
            int(m.group(1)) >= max_replicas,
            f"server-template has {m.group(1)} slots, fewer than the HPA's maxReplicas "
            f"{max_replicas}",
        )
    b = re.search(r"^\s*bind \S*:(\d+) ", cfg, re.M)
    check(
        b and int(b.group(1)) in proxy_ports,
        "HAProxy's bind port is not the proxy container's port",
    )


# ------------------------------------------------------------------------------------- main


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--src", required=True)
    ap.add_argument("--bin", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--k8s")
    a = ap.parse_args()
    server_bin = os.path.join(a.bin, "server/inbetween-server")
    loadgen_bin = os.path.join(a.bin, "tools/loadgen/inbetween-loadgen")
    server_flags = help_flags([server_bin])
    loadgen_flags = help_flags([loadgen_bin])
    gateway_flags = gateway_options(os.path.join(a.src, "client/web/src/gateway/main.mjs"))
    check(
        "--store" in server_flags and "--target" in loadgen_flags and "--upstream" in gateway_flags,
        "could not read the programs' flags from --help",
    )

    procs = Processes(a.work)
    try:
        # The HEALTHCHECK script itself: SERVING, an unknown service, nothing listening, and a
        # server with --tokens (probes carry no token).
        tokens = os.path.join(a.work, "tokens")
        with open(tokens, "w") as f:
            f.write("secret-probe probe\n")
        addr = start_server(
            procs, server_bin, "health", ["--listen", "127.0.0.1:0", "--tokens", tokens]
        )
        if addr:
            rc, out = healthcheck(a.src, addr)
            check(
                rc == 0 and out == "SERVING",
                f"healthcheck.py on a server with --tokens: {rc} {out}",
            )
            rc, out = healthcheck(a.src, addr, "no.such.Service")
            check(rc == 1, f"healthcheck.py accepted an unknown service: {rc} {out}")
        rc, out = healthcheck(a.src, f"127.0.0.1:{free_port()}")
        check(rc == 1, f"healthcheck.py accepted a port nobody listens on: {rc} {out}")
        check_health_answers(a.src)

        images = check_dockerfile(a.src, a.bin, server_flags, gateway_flags)
        check_runtime_packages(a.src, [server_bin, loadgen_bin])
        compose = check_compose(a.src, images, server_flags, loadgen_flags, gateway_flags)
        check_secrets_not_committed(a.src, compose["secret_files"])
        run_compose_locally(a.src, a.bin, procs, a.work, compose)
        if a.k8s:
            check_k8s(a.src, a.bin, procs, a.work, a.k8s, server_flags)
    finally:
        procs.stop_all()
    if FAILURES:
        print(f"containers_check: {len(FAILURES)} failure(s)", file=sys.stderr)
        sys.exit(1)
    print("containers_check: ok")


if __name__ == "__main__":
    main()
