# A stand-in for the official postgres:15 image, for machines with no registry (the CI machines):
# Debian's PostgreSQL 15 with an entry point that honours the same variables the official image
# documents (POSTGRES_USER, POSTGRES_PASSWORD, POSTGRES_DB, PGDATA), so docker/k8s/postgres.yaml
# runs unchanged on either. scripts/kube-smoke.sh builds it (context: docker/) and tags it docker.io/library/postgres:15
# in the local store only. On a real cluster use the official image or a managed database.
FROM debian:bookworm
ARG DEBIAN_FRONTEND=noninteractive
RUN apt-get update \
 && apt-get install -y --no-install-recommends postgresql-15 \
 && rm -rf /var/lib/apt/lists/*
COPY postgres-entrypoint.sh /usr/local/bin/postgres-entrypoint.sh
ENV PATH=/usr/lib/postgresql/15/bin:$PATH \
    PGDATA=/var/lib/postgresql/data
USER postgres
EXPOSE 5432
ENTRYPOINT ["/usr/local/bin/postgres-entrypoint.sh"]
