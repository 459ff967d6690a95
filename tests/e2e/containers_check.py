#!/usr/bin/python3
"""Checks docker/ and deploy/k8s/ without a container engine (driven by containers_test.sh).

Usage: containers_check.py --src SRC --bin BUILD_DIR --work DIR --redis-port PORT [--k8s RENDERED]
Static checks of docker/Dockerfile, docker/compose.yaml, docker/runtime-packages.txt and the
rendered `kubectl kustomize deploy/k8s` (RENDERED), then their commands run for real on loopback:
the servers started with the compose and Kubernetes flags (on a real Redis), the nginx entrypoint
in front of them, the HEALTHCHECK script and inbetween-loadgen with the compose arguments. Every
failure is listed; exit 1 if there is any. Needs Debian's python3-yaml and python3-grpcio
(/usr/bin/python3), apt-cache, dpkg, ldd, nginx, haproxy, node.
"""
import argparse
import fnmatch
import json
import os
import re
import shlex
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
    for d in ("build", "build/test", "build-server", "out", "client/web/node_modules"):
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
    )


def run_compose_locally(src, bin_dir, procs, work, redis_port, compose):
    """The compose services' commands on loopback: replicas on a real Redis, the proxy image's
    nginx entrypoint in front of them, the HEALTHCHECK script, inbetween-loadgen through nginx."""
    server_bin = os.path.join(bin_dir, "server/inbetween-server")
    addrs = {}
    for name, svc in sorted(compose["replicas"].items()):
        args = with_value(svc["command"], "--listen", "127.0.0.1:0")
        args = with_value(args, "--metrics-listen", "127.0.0.1:0")
        args = with_value(args, "--store", f"redis://127.0.0.1:{redis_port}")
        addrs[name] = start_server(procs, server_bin, f"compose-{name}", args)
    if not all(addrs.values()):
        return
    for name, addr in addrs.items():
        rc, out = healthcheck(src, addr)
        check(rc == 0, f"HEALTHCHECK against compose {name} ({addr}): {out}")
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

    # The load generator with the compose arguments: target nginx here, drawings from examples/,
    # a short bounded run.
    args = list(compose["loadgen_args"])
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
            f"compose on loopback: 3 replicas on Redis, nginx entrypoint, loadgen "
            f"{report['requests']} requests, {report['streams_completed']} streams, 0 lost"
        )


# ------------------------------------------------------------------------------- kubernetes


def labels_match(selector, labels):
    return bool(selector) and all(labels.get(k) == v for k, v in selector.items())


def check_k8s(src, bin_dir, procs, work, redis_port, rendered, server_flags):
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
    args = [
        re.sub(r"\$\(([A-Za-z_][A-Za-z0-9_]*)\)", lambda m: str(env.get(m.group(1), m.group(0))), a)
        for a in c.get("args", [])
    ]
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
    if check(m and redis, f"--store {store} is not redis://SERVICE:PORT, or no Redis workload"):
        svc = [s for s in services_for(redis[0]) if s["metadata"]["name"] == m.group(1)]
        check(
            svc and any(p["port"] == int(m.group(2)) for p in svc[0]["spec"]["ports"]),
            f"--store {store}: no Service of that name and port selects the Redis pods",
        )

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

    # The Deployment's args, run for real: a server on the test's Redis, health as the probes ask.
    run_args = with_value(args, "--listen", "127.0.0.1:0")
    run_args = with_value(run_args, "--metrics-listen", "127.0.0.1:0")
    run_args = with_value(run_args, "--store", f"redis://127.0.0.1:{redis_port}")
    addr = start_server(
        procs, os.path.join(bin_dir, "server/inbetween-server"), "k8s-server", run_args
    )
    if addr:
        rc, out = healthcheck(src, addr, c["readinessProbe"]["grpc"]["service"])
        check(rc == 0, f"the Deployment's server does not answer its probe's health check: {out}")
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
    ap.add_argument("--redis-port", required=True, type=int)
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
        run_compose_locally(a.src, a.bin, procs, a.work, a.redis_port, compose)
        if a.k8s:
            check_k8s(a.src, a.bin, procs, a.work, a.redis_port, a.k8s, server_flags)
    finally:
        procs.stop_all()
    if FAILURES:
        print(f"containers_check: {len(FAILURES)} failure(s)", file=sys.stderr)
        sys.exit(1)
    print("containers_check: ok")


if __name__ == "__main__":
    main()
