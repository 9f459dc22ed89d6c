# Multi-stage build: compile in the Rust image, run from a slim Debian as a non-root user.
FROM rust:1-slim-bookworm AS build
WORKDIR /src
COPY . .
RUN cargo build --release --locked --bin nurbsx

FROM debian:bookworm-slim
RUN useradd --system --uid 10001 nurbsx
COPY --from=build /src/target/release/nurbsx /usr/local/bin/nurbsx
USER nurbsx
EXPOSE 8080
ENV RUST_LOG=info
ENTRYPOINT ["nurbsx"]
CMD ["serve", "--addr", "0.0.0.0:8080"]
