#!/usr/bin/env python3
"""Checks the deploy/ manifests: YAML and XML well-formed, the fields each
kind needs present and consistent with each other and with the daemon
(probe paths, ports, exit codes of obscura batch).

    python3 tests/deploy/check_manifests.py [deploy]

Prints one line per check; exits 1 if any failed."""
import glob
import os
import sys
import xml.etree.ElementTree as ET

import yaml

root = sys.argv[1] if len(sys.argv) > 1 else "deploy"
passed = failed = 0


def check(name, cond):
    global passed, failed
    if cond:
        passed += 1
        print("  ok   " + name)
    else:
        failed += 1
        print("  FAIL " + name)


def get(d, *path, default=None):
    for p in path:
        if isinstance(d, dict) and p in d:
            d = d[p]
        elif isinstance(d, list) and isinstance(p, int) and p < len(d):
            d = d[p]
        else:
            return default
    return d


docs = {}
for f in sorted(glob.glob(os.path.join(root, "kubernetes", "*.yaml"))):
    try:
        items = [d for d in yaml.safe_load_all(open(f)) if d]
        ok = all(isinstance(d, dict) and d.get("kind") and d.get("apiVersion") for d in items)
        check(f"{os.path.basename(f)}: well-formed, apiVersion and kind", ok and len(items) > 0)
        for d in items:
            docs.setdefault(d["kind"], []).append((os.path.basename(f), d))
    except yaml.YAMLError as e:
        check(f"{os.path.basename(f)}: YAML ({e})", False)

kust = docs["Kustomization"][0][1]
for r in kust.get("resources", []):
    check(f"kustomization resource {r} exists", os.path.exists(os.path.join(root, "kubernetes", r)))

dep = [d for f, d in docs.get("Deployment", []) if f == "deployment.yaml"][0]
labels = get(dep, "spec", "selector", "matchLabels")
tmpl = get(dep, "spec", "template")
check("Deployment: selector matches the pod labels",
      labels and all(get(tmpl, "metadata", "labels", k) == v for k, v in labels.items()))
c = get(tmpl, "spec", "containers", 0)
check("Deployment: a container with image and args", c and c.get("image") and c.get("args"))
port = get(c, "ports", 0, "containerPort")
check("Deployment: listens on 0.0.0.0:<containerPort>", port and f"0.0.0.0:{port}" in c.get("args", []))
check("Deployment: readiness on /readyz, liveness on /healthz",
      get(c, "readinessProbe", "httpGet", "path") == "/readyz" and
      get(c, "livenessProbe", "httpGet", "path") == "/healthz")
check("Deployment: resource requests (cpu, memory)",
      get(c, "resources", "requests", "cpu") and get(c, "resources", "requests", "memory"))
check("Deployment: runs as non-root", get(tmpl, "spec", "securityContext", "runAsNonRoot") is True)
# the program cache: a writable volume at the image's OBSCURA_CACHE_DIR,
# filled from the image's warm cache by an init container
vols = {v.get("name"): v for v in get(tmpl, "spec", "volumes", default=[]) or []}
mounts = {m.get("mountPath"): m.get("name") for m in c.get("volumeMounts", []) or []}
inits = get(tmpl, "spec", "initContainers", default=[]) or []
cache_vol = mounts.get("/var/cache/obscura")
check("Deployment: the program cache is a writable volume at /var/cache/obscura, filled from the image",
      cache_vol in vols and "emptyDir" in vols[cache_vol] and
      any(any(m.get("name") == cache_vol for m in i.get("volumeMounts", []) or []) and
          "/var/cache/obscura/." in " ".join(i.get("command", [])) for i in inits))
check("Deployment: Prometheus scrape annotations on /metrics",
      get(tmpl, "metadata", "annotations", "prometheus.io/scrape") == "true" and
      get(tmpl, "metadata", "annotations", "prometheus.io/path") == "/metrics")
check("Deployment: a grace period for the SIGTERM drain",
      (get(tmpl, "spec", "terminationGracePeriodSeconds") or 0) >= 30)

gpu = [d for f, d in docs.get("Deployment", []) if f == "gpu-patch.yaml"][0]
gc = get(gpu, "spec", "template", "spec", "containers", 0)
check("gpu-patch: nvidia.com/gpu requested, graphics capability, egl-device",
      get(gc, "resources", "limits", "nvidia.com/gpu") == 1 and
      any(e.get("name") == "NVIDIA_DRIVER_CAPABILITIES" and "graphics" in e.get("value", "")
          for e in gc.get("env", [])) and "egl-device" in gc.get("args", []))

svc = docs["Service"][0][1]
check("Service: selects the Deployment's pods",
      all(get(tmpl, "metadata", "labels", k) == v for k, v in get(svc, "spec", "selector").items()))
check("Service: port targets the container's port name",
      get(svc, "spec", "ports", 0, "targetPort") == get(c, "ports", 0, "name"))

hpa = docs["HorizontalPodAutoscaler"][0][1]
check("HPA: scales the Deployment, min <= max, a metric",
      get(hpa, "spec", "scaleTargetRef", "name") == dep["metadata"]["name"] and
      get(hpa, "spec", "minReplicas") <= get(hpa, "spec", "maxReplicas") and
      len(get(hpa, "spec", "metrics", default=[])) >= 1)

sm = docs["ServiceMonitor"][0][1]
check("ServiceMonitor: selects the Service, scrapes /metrics on its port",
      all(get(svc, "metadata", "labels", k) == v for k, v in get(sm, "spec", "selector", "matchLabels").items()) and
      get(sm, "spec", "endpoints", 0, "path") == "/metrics" and
      get(sm, "spec", "endpoints", 0, "port") == get(svc, "spec", "ports", 0, "name"))

job = [d for f, d in docs["Job"] if f == "batch-job.yaml"][0]
js = job["spec"]
check("Job: Indexed, completions, restartPolicy Never",
      js.get("completionMode") == "Indexed" and js.get("completions", 0) > 0 and
      get(js, "template", "spec", "restartPolicy") == "Never")
rules = get(js, "podFailurePolicy", "rules", default=[])
fail_codes = [v for r in rules if r.get("action") == "FailJob" for v in get(r, "onExitCodes", "values", default=[])]
count_codes = [v for r in rules if r.get("action") == "Count" for v in get(r, "onExitCodes", "values", default=[])]
check("Job: podFailurePolicy fails fast on exit 3 (bad input), retries exit 4",
      3 in fail_codes and 4 in count_codes and 4 not in fail_codes)
jc = get(js, "template", "spec", "containers", 0)
script = " ".join(jc.get("command", []) + jc.get("args", []))
check("Job: runs obscura batch over a chunk from JOB_COMPLETION_INDEX",
      "obscura batch" in script and "JOB_COMPLETION_INDEX" in script and "--frames" in script)
check("Job: the container named in the exit-code rules exists",
      all(get(r, "onExitCodes", "containerName") in (None, jc.get("name")) for r in rules))

farm = os.path.join(root, "farm")
try:
    spec = ET.parse(os.path.join(farm, "opencue_job.xml")).getroot()
    cmd = spec.find("./job/layers/layer/cmd").text
    check("OpenCue: a layer runs obscura batch with #FRAME_START#-#FRAME_END#, range and chunk",
          "obscura batch" in cmd and "#FRAME_START#-#FRAME_END#" in cmd and
          spec.find("./job/layers/layer/range") is not None and spec.find("./job/layers/layer/chunk") is not None)
except (ET.ParseError, AttributeError) as e:
    check(f"OpenCue: opencue_job.xml ({e})", False)
try:
    t = yaml.safe_load(open(os.path.join(farm, "openjd_job.yaml")))
    step = t["steps"][0]
    tp = step["parameterSpace"]["taskParameterDefinitions"][0]
    params = {p["name"] for p in t["parameterDefinitions"]}
    data = step["script"]["embeddedFiles"][0]["data"]
    used = {w.split("}}")[0] for w in (yaml.safe_dump(t).split("{{Param.")[1:])}
    check("OpenJD: jobtemplate-2023-09, a chunked INT task parameter, obscura batch per task",
          t["specificationVersion"] == "jobtemplate-2023-09" and tp["type"] == "INT" and
          ":{{Param.ChunkSize}}" in tp["range"] and "obscura batch" in data and
          "{{Task.Param.ChunkStart}}" in data)
    check("OpenJD: every {{Param.X}} used is defined (" + ", ".join(sorted(used)) + ")", used <= params)
except (yaml.YAMLError, KeyError, IndexError, TypeError) as e:
    check(f"OpenJD: openjd_job.yaml ({e})", False)

# ---- the bake spread over shards: Kubernetes, OpenJD, OpenCue ----------
# With OBSCURA (the binary) and OBSCURA_BAKE_LEVEL (a level file), each
# template's commands run here: its shards, then its merge, on the level
# with few rays, and the merged .glb must be the unsharded bake's bytes.
import re
import shutil
import subprocess
import tempfile

obscura = os.environ.get("OBSCURA")
level = os.environ.get("OBSCURA_BAKE_LEVEL")
RAYS = "16"


def run_sh(script, env, cwd):
    e = dict(os.environ)
    e.update(env)
    r = subprocess.run(["/bin/sh", "-c", script], env=e, cwd=cwd, capture_output=True, text=True, timeout=300)
    if r.returncode != 0:
        print("       " + (r.stderr or r.stdout).strip().replace("\n", "\n       "))
    return r.returncode == 0


def unsharded(tmp, cmd="bake", ext=".glb"):
    out = os.path.join(tmp, "whole" + ext)
    subprocess.run([obscura, cmd, level, "-o", out, "--rays", RAYS, "-q"], check=True, timeout=300)
    return open(out, "rb").read()


def check_bake_job(fname, cmd, prefix, suffix, ext):
    """A shard Job and a merge Job of `obscura CMD` in kubernetes/FNAME;
    with OBSCURA and the level, their commands run here, merged =
    unsharded (the merge writes <level>SUFFIX)."""
    tag = os.path.splitext(fname)[0]
    jobs = {d["metadata"]["name"]: d for f, d in docs["Job"] if f == fname}
    sj, mj = jobs.get(prefix + "-shards"), jobs.get(prefix + "-merge")
    check(f"{tag}: a shard Job and a merge Job", sj is not None and mj is not None)
    if not (sj and mj):
        return
    ss = sj["spec"]
    sc = get(ss, "template", "spec", "containers", 0)
    senv = {e["name"]: e["value"] for e in sc.get("env", [])}
    mc = get(mj, "spec", "template", "spec", "containers", 0)
    menv = {e["name"]: e["value"] for e in mc.get("env", [])}
    winit = get(mj, "spec", "template", "spec", "initContainers", 0)
    wenv = {e["name"]: e["value"] for e in winit.get("env", [])}
    check(f"{tag}: shards Indexed, restartPolicy Never, completions = SHARDS of every container",
          ss.get("completionMode") == "Indexed" and get(ss, "template", "spec", "restartPolicy") == "Never" and
          str(ss.get("completions")) == senv.get("SHARDS") == menv.get("SHARDS") == wenv.get("SHARDS"))
    sscript = " ".join(sc.get("args", []))
    check(f"{tag}: shard i runs obscura {cmd} --shard $JOB_COMPLETION_INDEX/$SHARDS",
          f"obscura {cmd} " in sscript and '--shard "$JOB_COMPLETION_INDEX/$SHARDS"' in sscript)
    check(f"{tag}: the merge waits for the parts, with a deadline, and merges them",
          "--merge" in " ".join(mc.get("args", [])) and "part_" in " ".join(winit.get("args", [])) and
          (get(mj, "spec", "activeDeadlineSeconds") or 0) > 0)
    codes = [v for r in get(ss, "podFailurePolicy", "rules", default=[]) if r.get("action") == "FailJob"
             for v in get(r, "onExitCodes", "values", default=[])]
    check(f"{tag}: exit 3 (bad input) fails the shard Job at once", 3 in codes)
    check(f"{tag}: same level for shards and merge, same claim",
          senv.get("LEVEL") == menv.get("LEVEL") and
          get(ss, "template", "spec", "volumes", 0, "persistentVolumeClaim", "claimName") ==
          get(mj, "spec", "template", "spec", "volumes", 0, "persistentVolumeClaim", "claimName"))
    if obscura and level:
        tmp = tempfile.mkdtemp(prefix="obs_bakejob_")
        name = os.path.basename(level)
        shutil.copy(level, os.path.join(tmp, name))
        fix = lambda s: s.replace("/levels", tmp).replace("exec obscura ", f"exec {obscura} ")
        n = 4  # fewer shards than the example's 8: the same commands
        env = {"LEVEL": name, "SHARDS": str(n), "RAYS": RAYS}
        ok = all(run_sh(fix(sscript), dict(env, JOB_COMPLETION_INDEX=str(i)), tmp) for i in range(n))
        with open(os.path.join(tmp, "wait.sh"), "w") as w:
            w.write(fix(" ".join(winit.get("args", []))))
        ok = ok and run_sh("timeout 20 sh wait.sh", env, tmp)  # the parts are all there
        ok = ok and run_sh(fix(" ".join(mc.get("args", []))), env, tmp)
        out = os.path.join(tmp, os.path.splitext(name)[0] + suffix)
        check(f"{tag}: its commands run here ({n} shards of {name}, {RAYS} rays), merged = unsharded",
              ok and os.path.exists(out) and open(out, "rb").read() == unsharded(tmp, cmd, ext))
        shutil.rmtree(tmp)


check_bake_job("bake-job.yaml", "bake", "obscura-bake", "_baked.glb", ".glb")
check_bake_job("bake-dynamic-job.yaml", "bake-dynamic", "obscura-bake-dynamic", "_dynamic.json", ".json")

def check_openjd(fname, cmd, ext):
    """farm/FNAME, an OpenJD template of `obscura CMD` over shards: its
    steps and parameters; with OBSCURA and the level, its scripts run
    here, merged = unsharded (the output's extension EXT)."""
    tag = f"OpenJD {cmd}"
    try:
        t = yaml.safe_load(open(os.path.join(farm, fname)))
        steps = {s["name"]: s for s in t["steps"]}
        params = {p["name"]: p.get("default") for p in t["parameterDefinitions"]}
        used = {w.split("}}")[0] for w in (yaml.safe_dump(t).split("{{Param.")[1:])}
        check(f"{tag}: a Shards step over 1-{{{{Param.Shards}}}}, a Merge step that depends on it",
              get(steps, "Shards", "parameterSpace", "taskParameterDefinitions", 0, "range") ==
              "1-{{Param.Shards}}" and get(steps, "Merge", "dependencies", 0, "dependsOn") == "Shards")
        check(f"{tag}: every {{{{Param.X}}}} used is defined (" + ", ".join(sorted(used)) + ")",
              used <= set(params))
        sdata = steps["Shards"]["script"]["embeddedFiles"][0]["data"]
        mdata = steps["Merge"]["script"]["embeddedFiles"][0]["data"]
        check(f"{tag}: the shards run obscura {cmd} --shard, the merge --merge",
              f"exec obscura {cmd} " in sdata and "--shard" in sdata and
              f"exec obscura {cmd} " in mdata and "--merge" in mdata)
        if obscura and level:
            tmp = tempfile.mkdtemp(prefix="obs_openjd_")
            n = 3
            vals = dict(params, Level=level, Output=os.path.join(tmp, "out" + ext),
                        PartsDir=os.path.join(tmp, "parts"), Shards=n, Rays=RAYS)

            def fill(s, task=None):
                s = re.sub(r"\{\{Param\.(\w+)\}\}", lambda m: str(vals[m.group(1)]), s)
                s = s.replace("{{Task.Param.ShardNumber}}", str(task))
                return s.replace("exec obscura ", f"exec {obscura} ")
            ok = all(run_sh(fill(sdata, k), {}, tmp) for k in range(1, n + 1)) and run_sh(fill(mdata), {}, tmp)
            check(f"{tag}: its scripts run here ({n} shards, {RAYS} rays), merged = unsharded",
                  ok and open(vals["Output"], "rb").read() == unsharded(tmp, cmd, ext))
            shutil.rmtree(tmp)
    except (yaml.YAMLError, KeyError, IndexError, TypeError, OSError) as e:
        check(f"{tag}: {fname} ({e})", False)


def check_opencue(fname, cmd, rays, out):
    """farm/FNAME, an OpenCue job of `obscura CMD` over shards (its rays
    flag RAYS, its merge writing /show/levels/OUT): layers, dependency,
    frame range; with OBSCURA and the level, its commands run here,
    merged = unsharded."""
    tag = f"OpenCue {cmd}"
    try:
        spec = ET.parse(os.path.join(farm, fname)).getroot()
        layers = {l.get("name"): l for l in spec.findall("./job/layers/layer")}
        dep = spec.find("./depends/depend")
        job = spec.find("./job").get("name")
        check(f"{tag}: layers shards and merge, merge LAYER_ON_LAYER on shards of the same job",
              set(layers) == {"shards", "merge"} and dep is not None and dep.get("type") == "LAYER_ON_LAYER" and
              dep.find("deplayer").text == "merge" and dep.find("onlayer").text == "shards" and
              dep.find("depjob").text == job == dep.find("onjob").text)
        scmd, mcmd = layers["shards"].find("cmd").text, layers["merge"].find("cmd").text
        rng = layers["shards"].find("range").text
        n = int(rng.split("-")[1])
        check(f"{tag}: frames 1-{n} are shards 0..{n - 1} of {n}",
              rng == f"1-{n}" and f"exec obscura {cmd} " in scmd and f"--shard $((#IFRAME# - 1))/{n}" in scmd and
              f"exec obscura {cmd} " in mcmd and "--merge" in mcmd)
        if obscura and level:
            tmp = tempfile.mkdtemp(prefix="obs_opencue_")
            fix = lambda s: (s.replace("/show/levels/level.glb", level).replace("/show/levels", tmp)
                             .replace("exec obscura ", f"exec {obscura} ").replace(rays, "--rays " + RAYS))
            ok = all(run_sh(fix(scmd.replace("#IFRAME#", str(f))), {}, tmp) for f in range(1, n + 1))
            ok = ok and run_sh(fix(mcmd), {}, tmp)
            ext = os.path.splitext(out)[1]
            check(f"{tag}: its commands run here ({n} shards, {RAYS} rays), merged = unsharded",
                  ok and open(os.path.join(tmp, out), "rb").read() == unsharded(tmp, cmd, ext))
            shutil.rmtree(tmp)
    except (ET.ParseError, AttributeError, KeyError, ValueError, OSError) as e:
        check(f"{tag}: {fname} ({e})", False)


check_openjd("openjd_bake.yaml", "bake", ".glb")
check_openjd("openjd_bake_dynamic.yaml", "bake-dynamic", ".json")
check_opencue("opencue_bake.xml", "bake", "--rays 256", "level_baked.glb")
check_opencue("opencue_bake_dynamic.xml", "bake-dynamic", "--rays 1024", "level_dynamic.json")

print(f"manifests: {passed} passed, {failed} failed")
sys.exit(1 if failed else 0)
