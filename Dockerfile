# syntax=docker/dockerfile:1
# Multi-stage build: the web page in a Node image, the binary (which embeds the page's
# web/dist) in the Rust image, run from a slim Debian as a non-root user.
#
#   docker build -t nurbsx .
#   docker run --rm -p 8080:8080 nurbsx
#
# The build needs BuildKit (the default builder since Docker 23) for the cache mounts.

FROM node:20-bookworm-slim AS web
WORKDIR /web
COPY web/package.json web/package-lock.json ./
RUN npm ci --no-audit --no-fund
COPY web/ ./
RUN npm run build

FROM rust:1-slim-bookworm AS build
WORKDIR /src
COPY . .
# build.rs embeds web/dist into the binary.
COPY --from=web /web/dist web/dist
# The registry and target caches survive between builds; the binary is copied out of the
# target cache in the same step because cache mounts are not part of the image.
RUN --mount=type=cache,target=/usr/local/cargo/registry \
    --mount=type=cache,target=/src/target \
    cargo build --release --locked --bin nurbsx \
    && cp target/release/nurbsx /usr/local/bin/nurbsx

FROM debian:bookworm-slim
RUN useradd --system --uid 10001 --no-create-home --shell /usr/sbin/nologin nurbsx
COPY --from=build /usr/local/bin/nurbsx /usr/local/bin/nurbsx
USER nurbsx
EXPOSE 8080
ENV RUST_LOG=info
# Liveness probe without curl: bash's /dev/tcp sends GET /healthz and the status line must
# say 200. It targets the default port of the CMD below; change both together.
HEALTHCHECK --interval=30s --timeout=5s --start-period=5s --retries=3 \
    CMD ["bash", "-c", "exec 3<>/dev/tcp/127.0.0.1/8080 && printf 'GET /healthz HTTP/1.1\\r\\nHost: localhost\\r\\nConnection: close\\r\\n\\r\\n' >&3 && read -r status <&3 && [[ $status == *' 200 '* ]]"]
# nurbsx stops gracefully on SIGTERM (docker stop): requests in flight finish first.
STOPSIGNAL SIGTERM
ENTRYPOINT ["nurbsx"]
CMD ["serve", "--addr", "0.0.0.0:8080"]
