# protocol/: wire formats shared by the daemon and the clients (no GL,
# no sockets).  Included by the top Makefile.
PROTO_SRC := $(wildcard protocol/*.c)
PROTO_OBJ := $(PROTO_SRC:%.c=$(BUILD)/obj/%.o)
PROTO_LIB := $(BUILD)/libobscura_protocol.a

$(PROTO_LIB): $(PROTO_OBJ)
	@rm -f $@
	ar rcs $@ $^

-include $(PROTO_OBJ:.o=.d)
