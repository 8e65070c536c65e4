# nginx reverse proxy for docker/compose.yaml, from the same Debian base as the service so it
# builds where no registry is reachable (an official nginx image works too: mount nginx.conf
# and penumbra-proxy.conf into /etc/nginx/). Build context: docker/.
FROM debian:bookworm
ARG DEBIAN_FRONTEND=noninteractive
RUN apt-get update \
 && apt-get install -y --no-install-recommends nginx \
 && rm -rf /var/lib/apt/lists/* /etc/nginx/sites-enabled /etc/nginx/conf.d
COPY nginx.conf /etc/nginx/nginx.conf
COPY penumbra-proxy.conf /etc/nginx/penumbra-proxy.conf
# nginx.conf keeps every writable path under /tmp, so the proxy runs unprivileged.
USER www-data
EXPOSE 8080
STOPSIGNAL SIGQUIT
# -e stderr: do not even try the compiled-in /var/log/nginx/error.log.
ENTRYPOINT ["nginx", "-e", "stderr", "-g", "daemon off;"]
