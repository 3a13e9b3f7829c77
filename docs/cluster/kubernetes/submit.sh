#!/usr/bin/env bash
# Run the three stages of a sharded PIS run on Kubernetes, one after the other: trace
# (Indexed Job), solve (Indexed Job), merge (Job). See docs/CLUSTER.md.
#
# Usage: docs/cluster/kubernetes/submit.sh
#
# Uses kubectl's current context and namespace. Beforehand: the image pis:latest where the
# cluster can pull it, the scene copied onto the volume (PIS_SCENE in trace-job.yaml), the
# shard count and flags set in the Job files. Running it again resumes: a completed Job is
# left as it is, traced points and solved fragments are kept. A failed Job must be deleted
# (kubectl delete job/pis-trace) before it is applied again.
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)

kubectl apply -f "$here/pvc.yaml"
kubectl apply -f "$here/trace-job.yaml"
kubectl wait --for=condition=complete job/pis-trace --timeout=24h
kubectl apply -f "$here/solve-job.yaml"
kubectl wait --for=condition=complete job/pis-solve --timeout=24h
kubectl apply -f "$here/merge-job.yaml"
kubectl wait --for=condition=complete job/pis-merge --timeout=24h
