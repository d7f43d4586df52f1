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

job = docs["Job"][0][1]
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

print(f"manifests: {passed} passed, {failed} failed")
sys.exit(1 if failed else 0)
