#!/usr/bin/env python3
"""Rewrites docker/k8s/*.yaml for `podman kube play` (podman 4.3), on standard output.

What podman 4.3 does differently from Kubernetes, and what this changes for it:
- it publishes every containerPort on the host's port of the same number, so two replicas of one
  Deployment collide: the `ports` lists are dropped (the probes name port 8080 by number, and
  nothing else needs them: the pods are reached by their pod IPs on podman's bridge);
- it has no registry here: images are replaced by the locally built ones (--image NAME=REF);
- Services and Secrets are not played (the secret is made with `podman secret create`);
  they are dropped so the play does not stop on them.
Everything else (Deployments with replicas, probes, resources, security contexts, emptyDir, the
ReadWriteMany claim as a shared named volume, secretKeyRef env) plays as written.
"""
import argparse
import sys

import yaml


def main() -> int:
    parser = argparse.ArgumentParser()
    parser.add_argument("manifest")
    parser.add_argument("--image", action="append", default=[], help="NAME=REF")
    args = parser.parse_args()
    images = dict(item.split("=", 1) for item in args.image)
    with open(args.manifest, encoding="utf-8") as f:
        docs = [d for d in yaml.safe_load_all(f) if d]
    out = []
    for doc in docs:
        if doc.get("kind") in ("Service", "Secret"):
            continue
        if doc.get("kind") == "Deployment":
            for container in doc["spec"]["template"]["spec"]["containers"]:
                container.pop("ports", None)
                if container["image"] in images:
                    container["image"] = images[container["image"]]
        out.append(doc)
    yaml.safe_dump_all(out, sys.stdout, sort_keys=False)
    return 0


if __name__ == "__main__":
    sys.exit(main())
