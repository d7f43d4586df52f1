/* The daemon's lists of connections and subscribers: intrusive, doubly
 * linked through `prev` and `next`, headed by a pointer (NULL: empty).
 * The caller holds the lock that guards the list. */
#ifndef OBSD_LIST_H
#define OBSD_LIST_H

/* n in front of the list at head. */
#define OBSD_LIST_PUSH(head, n)           \
    do {                                  \
        (n)->prev = NULL;                 \
        (n)->next = (head);               \
        if (head)                         \
            (head)->prev = (n);           \
        (head) = (n);                     \
    } while (0)

/* n out of the list at head. */
#define OBSD_LIST_UNLINK(head, n)         \
    do {                                  \
        if ((n)->prev)                    \
            (n)->prev->next = (n)->next;  \
        else                              \
            (head) = (n)->next;           \
        if ((n)->next)                    \
            (n)->next->prev = (n)->prev;  \
    } while (0)

#endif
